# bench/tuner: the seeds' validation of the thread-count model on the 2-D
# diffusion example (see docs/tuner.md for the command and the results).
add_executable(tuner_bench tuner.c)
set_target_properties(tuner_bench PROPERTIES OUTPUT_NAME tuner)
target_link_libraries(tuner_bench PRIVATE silc_diffusion)

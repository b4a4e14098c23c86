# Tests of the examples and the silc command (included from tests/CMakeLists.txt,
# after silc_add_test has made test_examples from test_examples.c).  The test
# links the examples' shared code so it checks exactly what the examples run.
if(NOT TARGET test_examples)
  silc_add_test(test_examples SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_examples.c)
endif()
target_link_libraries(test_examples PRIVATE silc_diffusion)

# The example programs themselves run end to end (small sizes, to stay quick).
add_test(NAME example_diffusion1d COMMAND diffusion1d 50 100 0.5)
add_test(NAME example_diffusion2d
         COMMAND diffusion2d -n 30 -s 5 -o ${CMAKE_CURRENT_BINARY_DIR}/diffusion2d_test.pgm)
add_test(NAME test_cli COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_cli.sh $<TARGET_FILE:silc_cli>)
set_tests_properties(example_diffusion1d example_diffusion2d test_cli PROPERTIES
  ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)

# The cloth program (examples/cloth, built when libpng is found): its
# drivers against each other and physics, its scene reader and its frames.
if(TARGET silc_cloth)
  silc_add_test(test_cloth_example SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cloth_example.c)
  target_link_libraries(test_cloth_example PRIVATE silc_cloth)
  foreach(t scene frame)
    silc_add_test(test_cloth_${t} SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cloth_${t}.c)
    target_link_libraries(test_cloth_${t} PRIVATE silc_cloth)
  endforeach()
  set_tests_properties(test_cloth_scene PROPERTIES
    ENVIRONMENT "${SILC_TEST_ENV};SILC_CLOTH_SCENES=${PROJECT_SOURCE_DIR}/examples/cloth/scenes")
  # Physics, accuracy and the checks that make wrong runs speak; it runs the
  # program too.
  silc_add_test(test_cloth_physics SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cloth_physics.c)
  target_link_libraries(test_cloth_physics PRIVATE silc_cloth)
  target_compile_definitions(test_cloth_physics PRIVATE CLOTH_PROGRAM="$<TARGET_FILE:cloth>"
                             CLOTH_SCRATCH="${CMAKE_CURRENT_BINARY_DIR}")
  add_dependencies(test_cloth_physics cloth)
  set_tests_properties(test_cloth_physics PROPERTIES
    ENVIRONMENT "${SILC_TEST_ENV};SILC_CLOTH_SCENES=${PROJECT_SOURCE_DIR}/examples/cloth/scenes")
  # The plain-C step cloth_bench --seed-statements measures the cmp
  # statements against does their work (bench/cloth_c_step.c).
  silc_add_test(test_cloth_c_step SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cloth_c_step.c
                ${PROJECT_SOURCE_DIR}/bench/cloth_c_step.c)
  target_link_libraries(test_cloth_c_step PRIVATE silc_cloth)
  target_include_directories(test_cloth_c_step PRIVATE ${PROJECT_SOURCE_DIR}/bench)
  set_tests_properties(test_cloth_c_step PROPERTIES
    ENVIRONMENT "${SILC_TEST_ENV};SILC_CLOTH_SCENES=${PROJECT_SOURCE_DIR}/examples/cloth/scenes")
  add_test(NAME example_cloth COMMAND cloth ${PROJECT_SOURCE_DIR}/examples/cloth/scenes/hanging.scene
           --mode cmp --steps 20 --frames ${CMAKE_CURRENT_BINARY_DIR}/cloth-frames)
  set_tests_properties(example_cloth PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)
  # Its progress line: on a terminal only (tools/progress.h, as the benches').
  add_test(NAME test_progress COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_progress.sh $<TARGET_FILE:cloth>
           ${PROJECT_SOURCE_DIR}/examples/cloth/scenes/hanging.scene)
  set_tests_properties(test_progress PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 120)
endif()

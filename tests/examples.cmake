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

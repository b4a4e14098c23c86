# bench/cloth (included from bench/CMakeLists.txt): the cloth example's three
# drivers timed against each other; bench/cloth.sh runs it embedded and
# through silcd.  Built with the example (libpng).  Not a test.
if(TARGET silc_cloth)
  add_executable(cloth_bench cloth.c cloth_c_step.c)
  target_link_libraries(cloth_bench PRIVATE silc_cloth)
endif()

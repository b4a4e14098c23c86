# bench/remote (included from bench/CMakeLists.txt): remote-mode throughput,
# latency and the diffusion loop against a silcd it starts itself.
if(TARGET silcd)
  find_package(Threads REQUIRED)
  add_executable(remote remote.c)
  target_link_libraries(remote PRIVATE silc_diffusion Threads::Threads ${MATH_LIB})
  target_compile_definitions(remote PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>")
  add_dependencies(remote silcd)
endif()

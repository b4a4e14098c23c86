# bench/iterative: SpMV of plugin-lis-style against STREAM triad, and the
# speed/accuracy trade of the iterative backends on the 500x500 Laplacian
# (see the head of bench/iterative.c).  It compiles the plugin's own kernel
# file, so the SpMV timed is the one the plugin runs.  Include this file from
# bench/CMakeLists.txt.
find_package(OpenMP COMPONENTS C)
add_executable(iterative ${CMAKE_CURRENT_LIST_DIR}/iterative.c
  ${PROJECT_SOURCE_DIR}/plugin-lis-style/lis_kernels.c)
target_include_directories(iterative PRIVATE ${PROJECT_SOURCE_DIR}/plugin-lis-style
  ${PROJECT_SOURCE_DIR}/core/include)
target_compile_definitions(iterative PRIVATE SILC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(iterative PRIVATE silc ${MATH_LIB})
if(OpenMP_C_FOUND)
  target_link_libraries(iterative PRIVATE OpenMP::OpenMP_C)
endif()

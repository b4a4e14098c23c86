# bench/accuracy: time against forward and backward error for every backend
# and knob on generated families; tables on stdout, one SVG per problem in
# docs/accuracy/ (see the head of bench/accuracy.c and docs/accuracy.md).
add_executable(accuracy ${CMAKE_CURRENT_LIST_DIR}/accuracy.c)
target_include_directories(accuracy PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/core/include)
target_compile_definitions(accuracy PRIVATE SILC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(accuracy PRIVATE silc ${MATH_LIB})

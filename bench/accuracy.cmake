# bench/accuracy: time against forward and backward error for every backend
# and knob on generated families; tables on stdout, one SVG per problem in
# docs/accuracy/ (see the head of bench/accuracy.c and docs/accuracy.md).
add_executable(accuracy ${CMAKE_CURRENT_LIST_DIR}/accuracy.c)
target_include_directories(accuracy PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/core/include)
target_compile_definitions(accuracy PRIVATE SILC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(accuracy PRIVATE silc ${MATH_LIB})

# bench/accuracy_condest: the condition estimate's cost next to the
# factorization, per shared matrix and backend (docs/accuracy.md).
add_executable(accuracy_condest ${CMAKE_CURRENT_LIST_DIR}/accuracy_condest.c)
target_include_directories(accuracy_condest PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/core/include)
target_compile_definitions(accuracy_condest PRIVATE SILC_SHARED_MATRICES="${PROJECT_SOURCE_DIR}/../shared/matrices")
target_link_libraries(accuracy_condest PRIVATE silc ${MATH_LIB})

# bench/complex_condest: what the complex estimate's start block costs
# under accuracy.condest = auto (UMFPACK, KLU), on examples/helmholtz's matrix.
if(TARGET silc_helmholtz)
  add_executable(complex_condest ${CMAKE_CURRENT_LIST_DIR}/complex_condest.c)
  target_link_libraries(complex_condest PRIVATE silc_helmholtz silc ${MATH_LIB})
endif()

# tests/mps.cmake -- the MPS dam break (examples/mps, Java): the model's unit
# test and the dam break against Martin & Moyce per backend config, each run
# by examples/mps/test_mps.sh against a silcd it starts with that config.
# Skipped without the Java client; a config whose plugin (or, for PETSc,
# hypre) is missing skips (77).
if(TARGET mps AND TARGET silcd AND SILC_MPS_CP)
  set(_mps sh ${SILC_MPS_DIR}/test_mps.sh $<TARGET_FILE:silcd> ${SILC_MPS_CP} ${SILC_MPS_DIR} ${SILC_MPS_BIN}/runs)
  set(_mps_env OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1)
  # The model: lattice number density, the PPE matrix, a resting column
  # (against a silcd with the built-in dispatch: any solver will do).
  add_test(NAME mps_model COMMAND ${_mps} model)
  # Timeouts catch a hang, not slowness: a dam break takes 5-8 s on a quiet
  # machine but passed 60 s at a load average of 20 on the shared 2-core VM.
  set_tests_properties(mps_model PROPERTIES TIMEOUT 180 ENVIRONMENT "${_mps_env}")
  set(_plugin_iccg silc_plugin_lis-style)
  set(_plugin_cholmod silc_plugin_suitesparse)
  set(_plugin_petsc-amg silc_plugin_petsc)
  foreach(cfg iccg cholmod petsc-amg)
    set(_plugin none)
    if(TARGET ${_plugin_${cfg}})
      set(_plugin $<TARGET_FILE:${_plugin_${cfg}}>)
    endif()
    add_test(NAME mps_dambreak_${cfg} COMMAND ${_mps} dambreak ${cfg} ${_plugin})
    set_tests_properties(mps_dambreak_${cfg} PROPERTIES TIMEOUT 300 ENVIRONMENT "${_mps_env}"
      SKIP_RETURN_CODE 77 FIXTURES_SETUP mps_run_${cfg})
  endforeach()
  # The backends' front curves agree (those that ran).
  add_test(NAME mps_backends_agree COMMAND ${_mps} agree)
  set_tests_properties(mps_backends_agree PROPERTIES TIMEOUT 60 ENVIRONMENT "${_mps_env}"
    FIXTURES_REQUIRED "mps_run_iccg;mps_run_cholmod" DEPENDS mps_dambreak_petsc-amg)
endif()

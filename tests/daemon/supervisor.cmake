# daemon/supervisor: the state machine alone.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_supervisor.cpp hsa_daemon_supervisor)
# What the properties below found, shrunk, as ordinary tests.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_supervisor_regressions.cpp hsa_daemon_supervisor)
# The excitation the supervisor generates (excite).
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_supervisor_excitation.cpp hsa_daemon_supervisor)
# Its rules on random event sequences (rapidcheck; a fixed seed and count, see the file).
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_supervisor_properties.cpp hsa_daemon_supervisor rapidcheck_gtest)
# Moves bounded by what the plant can follow in the direction they travel.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_supervisor_capability.cpp hsa_daemon_supervisor)
# A streamed setpoint through the supervisor's limiter (control/setpoint_limiter).
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_supervisor_stream_limiter.cpp hsa_daemon_supervisor)

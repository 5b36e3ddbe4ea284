# daemon/supervisor: the state machine alone.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_supervisor.cpp hsa_daemon_supervisor)
# What the properties below found, shrunk, as ordinary tests.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_supervisor_regressions.cpp hsa_daemon_supervisor)

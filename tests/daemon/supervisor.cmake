# daemon/supervisor: the state machine alone.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_supervisor.cpp hsa_daemon_supervisor)

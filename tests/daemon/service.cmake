hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_systemd_watchdog.cpp TIMING THREADS hsa_daemon_service)

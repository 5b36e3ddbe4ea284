# Tests of daemon/rt (included by tests/daemon/CMakeLists.txt). None asserts timing: the VM is noisy.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_rt_next_deadline.cpp hsa::daemon_rt)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_rt_histogram.cpp hsa::daemon_rt)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_housekeeping_affinity.cpp THREADS hsa::daemon_rt)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_rt_stats_recorder.cpp THREADS hsa::daemon_rt)
# Without hsa_rt_counters: the weak counters of a production build.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_rt_executive.cpp TIMING THREADS hsa::daemon_rt)
# With hsa_rt_counters: the allocation, lock and page-fault counters of a test build.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_rt_counters.cpp hsa::daemon_rt hsa::rt_counters)

# Tests of daemon/lcm_bridge. Included by tests/daemon/CMakeLists.txt.

# Pure tests: no network, discovered and run like every other unit test.
hsa_add_gtest(daemon test_lcm_validation.cpp hsa_daemon_lcm_bridge)
hsa_add_gtest(daemon test_message_authenticator.cpp hsa_daemon_lcm_bridge)
hsa_add_gtest(daemon test_command_lease.cpp hsa_daemon_lcm_bridge)
hsa_add_gtest(daemon test_lcm_receive_filter.cpp hsa_daemon_lcm_bridge)
hsa_add_gtest(daemon test_lcm_socket_guard.cpp hsa_daemon_lcm_bridge)

# The loopback test sends LCM multicast, so it runs only inside a private network
# namespace. It is one ctest entry wrapping the whole gtest binary, never gtest_discover_tests,
# which would register its cases to run on the host network. The binary itself also refuses to
# run when it sees any interface but lo.
add_executable(daemon_lcm_loopback test_lcm_loopback.cpp)
target_link_libraries(daemon_lcm_loopback PRIVATE hsa_daemon_lcm_bridge GTest::gtest GTest::gtest_main)

# If the namespace cannot be made, the test fails and says why; it does not pass silently.
set(netns_runner "${CMAKE_CURRENT_BINARY_DIR}/run_in_netns.sh")
file(WRITE "${netns_runner}" [=[#!/bin/sh
# Runs "$@" in a private network namespace with only loopback, multicast routed to it.
if ! unshare -n true 2>/dev/null; then
  echo "FAIL: 'unshare -n' is not permitted here (needs root or CAP_SYS_ADMIN); LCM tests must run in a private network namespace and are not run on the host network." >&2
  exit 1
fi
exec unshare -n sh -c 'ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec "$0" "$@"' "$@"
]=])
add_dependencies(hsa_threaded_tests daemon_lcm_loopback)
add_test(NAME daemon.lcm_loopback COMMAND sh "${netns_runner}" "$<TARGET_FILE:daemon_lcm_loopback>")
set_tests_properties(daemon.lcm_loopback PROPERTIES LABELS "netns;daemon;timing;threads" TIMEOUT 120
  RUN_SERIAL TRUE)

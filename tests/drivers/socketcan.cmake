# The socketcan driver plugin's tests. Included from tests/drivers/CMakeLists.txt; sources are
# found relative to this file.
#
# Host tests (ctest): the codec, the settings, the frame bookkeeping fed by hand, and the plugin
# refusing to configure on a kernel without CAN. This build machine's kernel has no AF_CAN, so
# everything that needs a real CAN socket is in kernel_socketcan_vcan below.
set(HSA_SOCKETCAN_TEST_DIR "${CMAKE_CURRENT_LIST_DIR}")

hsa_add_gtest(drivers "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_codec.cpp" hsa_socketcan_io)
hsa_add_gtest(drivers "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_settings.cpp" hsa_socketcan_io)
target_compile_definitions(drivers_socketcan_settings PRIVATE
  HSA_SOCKETCAN_EXAMPLE="${PROJECT_SOURCE_DIR}/systemd/hsad-socketcan.toml")
hsa_add_gtest(drivers "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_exchange.cpp" hsa_socketcan_io
  hsa_test_counting_allocator)
hsa_add_gtest(drivers "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_plugin.cpp" hsa_socketcan_io)
target_compile_definitions(drivers_socketcan_plugin PRIVATE HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(drivers_socketcan_plugin hsa_driver_socketcan)

# kernel_socketcan_vcan: the plugin on a real CAN kernel, against vcan0 and can-utils. Not a
# ctest test here: the real-kernel harness (tests/kernel/) runs it inside a qemu VM with vcan0 up,
# HSA_CAN_IFACE=vcan0 and candump/cansend on PATH. It loads the plugin from $HSA_PLUGIN_DIR
# (fallback: this build's plugin directory) and exits 77 (skip) when there is no CAN interface.
# Its last test runs hsa-simdev --can ($HSA_SIMDEV, fallback: this build's) and skips without it.
# Its own main() (GTest::gtest, not gtest_main) so that it can exit 77 before running tests.
add_executable(kernel_socketcan_vcan "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_vcan.cpp")
target_link_libraries(kernel_socketcan_vcan PRIVATE hsa_drivers hsa_test_counting_allocator
  GTest::gtest GTest::gmock)
target_compile_definitions(kernel_socketcan_vcan PRIVATE
  HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}"
  HSA_SIMDEV="$<TARGET_FILE:hsa-simdev>")
add_dependencies(kernel_socketcan_vcan hsa_driver_socketcan hsa-simdev)
# The test's own send() holds the plugin's watchdog thread inside its send (fault injection): the
# dlopened plugin binds to it only if the executable exports it.
target_link_options(kernel_socketcan_vcan PRIVATE "LINKER:--export-dynamic-symbol=send")

# hsa-simdev --can refusing to start on a kernel without CAN.
hsa_add_gtest(drivers "${HSA_SOCKETCAN_TEST_DIR}/test_socketcan_simdev.cpp")
target_compile_definitions(drivers_socketcan_simdev PRIVATE HSA_SIMDEV="$<TARGET_FILE:hsa-simdev>")
add_dependencies(drivers_socketcan_simdev hsa-simdev)

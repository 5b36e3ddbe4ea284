# The gpiod driver plugin's tests. Included from tests/drivers/CMakeLists.txt; sources are found
# relative to this file so a scratch build can include it too.
#
# On the host (this machine's kernel has no GPIO): the settings, the edge latch, the charge pump,
# and the plugin's configure error on a machine without GPIO. On a real kernel: `kernel_gpiod_sim`, run by the
# qemu harness in tests/kernel against a gpio-sim chip, and not registered with ctest here.
set(HSA_GPIOD_TEST_DIR "${CMAKE_CURRENT_LIST_DIR}")
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBGPIOD REQUIRED IMPORTED_TARGET libgpiod)

hsa_add_gtest(drivers "${HSA_GPIOD_TEST_DIR}/test_gpiod_settings.cpp" hsa_gpiod_io)
target_compile_definitions(drivers_gpiod_settings PRIVATE
  HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}"
  HSA_GPIOD_EXAMPLE="${PROJECT_SOURCE_DIR}/systemd/hsad-gpiod.toml")
add_dependencies(drivers_gpiod_settings hsa_driver_gpiod)

# The example configuration passes the daemon's own check (the plugin's table: test above).
add_test(NAME drivers.gpiod_example_config
  COMMAND $<TARGET_FILE:hsad> --check-config "${PROJECT_SOURCE_DIR}/systemd/hsad-gpiod.toml"
          --key-dir "${HSA_TEST_KEY_DIR}")
set_tests_properties(drivers.gpiod_example_config PROPERTIES LABELS "drivers")

hsa_add_gtest(drivers "${HSA_GPIOD_TEST_DIR}/test_gpiod_edge_latch.cpp" hsa_gpiod_io)
hsa_add_gtest(drivers "${HSA_GPIOD_TEST_DIR}/test_gpiod_charge_pump.cpp" hsa_gpiod_io hsa_test_counting_allocator)

# The real-kernel test. Its own main() exits 77 (skip) without HSA_GPIO_SIM_CHIP. Linked to
# libgpiod dynamically, like the plugin it loads, so `ldd kernel_gpiod_sim` lists every shared
# library the VM needs for both (libgpiod.so.2, libtomlplusplus.so.3, libstdc++, libc).
add_executable(kernel_gpiod_sim "${HSA_GPIOD_TEST_DIR}/test_gpiod_sim.cpp")
target_link_libraries(kernel_gpiod_sim PRIVATE
  hsa_drivers PkgConfig::LIBGPIOD hsa_test_counting_allocator GTest::gtest GTest::gmock)
target_compile_definitions(kernel_gpiod_sim PRIVATE HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(kernel_gpiod_sim hsa_driver_gpiod)

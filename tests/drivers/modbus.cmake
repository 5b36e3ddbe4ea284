# The modbus driver plugin's tests and hsa-simdev's. Included from tests/drivers/CMakeLists.txt;
# sources are found relative to this file so a scratch build can include it too.
# Peers: Debian's python3-pymodbus (run with /usr/bin/python3, which is the python that sees it)
# and mbpoll. Network: TCP on 127.0.0.1 only, ports chosen free at run time.
set(HSA_MODBUS_TEST_DIR "${CMAKE_CURRENT_LIST_DIR}")
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBMODBUS REQUIRED IMPORTED_TARGET libmodbus)
# mbpoll and socat (the RTU test's pseudo-terminal pair) are test tools only: without them those
# tests report SKIP, they do not pass.
find_program(HSA_MBPOLL mbpoll)
find_program(HSA_SOCAT socat)

hsa_add_gtest(drivers "${HSA_MODBUS_TEST_DIR}/test_modbus_codec.cpp" THREADS hsa_modbus_io)

hsa_add_gtest(drivers "${HSA_MODBUS_TEST_DIR}/test_modbus_settings.cpp" hsa_modbus_io)
target_compile_definitions(drivers_modbus_settings PRIVATE HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(drivers_modbus_settings hsa_driver_modbus)

hsa_add_gtest(drivers "${HSA_MODBUS_TEST_DIR}/test_modbus_pymodbus.cpp" TIMING THREADS hsa_drivers PkgConfig::LIBMODBUS hsa_test_counting_allocator)
target_compile_definitions(drivers_modbus_pymodbus PRIVATE
  HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}"
  HSA_PYMODBUS_SERVER="${HSA_MODBUS_TEST_DIR}/pymodbus_server.py"
  HSA_SOCAT="$<IF:$<BOOL:${HSA_SOCAT}>,${HSA_SOCAT},>")
add_dependencies(drivers_modbus_pymodbus hsa_driver_modbus)

hsa_add_gtest(drivers "${HSA_MODBUS_TEST_DIR}/test_modbus_simdev.cpp" TIMING THREADS hsa_drivers PkgConfig::LIBMODBUS)
target_compile_definitions(drivers_modbus_simdev PRIVATE
  HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}"
  HSA_SIMDEV="$<TARGET_FILE:hsa-simdev>"
  HSA_MBPOLL="$<IF:$<BOOL:${HSA_MBPOLL}>,${HSA_MBPOLL},>")
add_dependencies(drivers_modbus_simdev hsa_driver_modbus hsa-simdev)

# Timeouts on the real path: a small Modbus TCP peer in the test that falls silent or answers late.
hsa_add_gtest(drivers "${HSA_MODBUS_TEST_DIR}/test_modbus_timeout.cpp" TIMING THREADS hsa_drivers Threads::Threads)
target_compile_definitions(drivers_modbus_timeout PRIVATE HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(drivers_modbus_timeout hsa_driver_modbus)

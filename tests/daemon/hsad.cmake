# daemon/hsad: the driver set (the RT cycle's driver masks and the recovery an operator reset runs),
# on the loopback fixture plugin (tests/drivers) and the sim plugin.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_driver_set.cpp hsa_daemon_core hsa_test_counting_allocator)
target_compile_definitions(daemon_driver_set PRIVATE
  HSA_FIXTURE_LOOPBACK_PATH="$<TARGET_FILE:hsa_driver_fixture_loopback>"
  HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
add_dependencies(daemon_driver_set hsa_driver_fixture_loopback hsa_driver_sim)

# An operator reset recovering a failed driver, through hsad's pieces on the sim plugin.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_operator_reset.cpp hsa_daemon_core)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_command_results.cpp hsa_daemon_core)

# A command's way from the LCM side's port to the axis and its answer back, on the sim plugin.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_command_path.cpp hsa_daemon_core)
target_compile_definitions(daemon_command_path PRIVATE
  HSA_SIM_CONFIG="${PROJECT_SOURCE_DIR}/systemd/hsad-sim.toml")
add_dependencies(daemon_command_path hsa_driver_sim)
target_compile_definitions(daemon_operator_reset PRIVATE
  HSA_SIM_CONFIG="${PROJECT_SOURCE_DIR}/systemd/hsad-sim.toml")
add_dependencies(daemon_operator_reset hsa_driver_sim)

# One hsad per configuration, axis and I/O: the lock files a second hsad finds taken.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_instance_lock.cpp hsa_daemon_core)
target_compile_definitions(daemon_instance_lock PRIVATE HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
add_dependencies(daemon_instance_lock hsa_driver_modbus)

# The configuration's per-axis thresholds, in seconds, as the supervisor counts them.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_setup.cpp hsa_daemon_core)
target_compile_definitions(daemon_axis_setup PRIVATE
  HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# Which RT cycles publish telemetry: the one place it is decimated.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_tick_decimator.cpp hsa_daemon_core)

# hsad --stats-json: a document any JSON reader takes.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_stats_json.cpp hsa_daemon_core nlohmann_json::nlohmann_json)

# The operator thread's checks of an excitation (excite) before the RT thread runs it.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_excitation_gate.cpp hsa_daemon_core)
# MOVE_TO on the sim plugin with the example configuration's axis: overshoot, settling, saturation.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_moves.cpp hsa_daemon_core)
target_compile_definitions(daemon_moves PRIVATE HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}" HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(daemon_moves hsa_driver_sim)
# A healthy axis never faults from its operator's command: moves and streamed setpoints on the sim.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_never_faults.cpp hsa_daemon_core)
target_compile_definitions(daemon_never_faults PRIVATE HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}" HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(daemon_never_faults hsa_driver_sim)

# The flight recorder: its ring on two threads, and inside hsad's RT cycle on the sim plugin with
# the capture file read back through libmatio, and the folder's bounds.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_capture_ring.cpp THREADS hsa_daemon_recorder hsa_test_counting_allocator)
# The operator's triggers: a condition on the row's signals, and the checks of a CAPTURE command.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_capture_condition.cpp hsa_daemon_recorder hsa_test_counting_allocator)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_capture_gate.cpp hsa_daemon_core)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_recorder_cycle.cpp hsa_daemon_core PkgConfig::MATIO hsa_test_counting_allocator)
target_compile_definitions(daemon_recorder_cycle PRIVATE
  HSA_SIM_CONFIG="${PROJECT_SOURCE_DIR}/systemd/hsad-sim.toml")
add_dependencies(daemon_recorder_cycle hsa_driver_sim)

# hsad's Prometheus metrics: the exposition text, the metrics of a snapshot (checked by Debian's
# promtool, package prometheus), and the textfile written atomically by its own thread.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_prometheus_text.cpp hsa_daemon_core)
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_metrics_text.cpp THREADS hsa_daemon_core)
find_program(HSA_PROMTOOL promtool PATHS /usr/bin)
target_compile_definitions(daemon_metrics_text PRIVATE HSA_PROMTOOL="${HSA_PROMTOOL}")

# daemon/config: parsing, validation messages, and the example configurations in systemd/.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_config.cpp hsa_daemon_config)
target_compile_definitions(daemon_config PRIVATE HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# The bounds on the configuration text, checked before the TOML parser runs.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_input_bounds.cpp hsa_daemon_config)

# The motion bounds against the capability of the axis's plant-set file.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_config_capability.cpp hsa_daemon_config)
target_compile_definitions(daemon_config_capability PRIVATE HSA_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# [axes.valve_law]'s model-inverse feed-forward keys: read, described, and refused with file:line:key.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_config_valve_law.cpp hsa_daemon_config)

# [axes.valve_law.predictive]: read into the predictive law's matrices, described in eq 31's place,
# and refused with file:line:key, eq 31's keys beside it too.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_config_valve_predictive.cpp hsa_daemon_config)

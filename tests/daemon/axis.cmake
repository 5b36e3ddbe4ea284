# daemon/axis: the axis loop against the real sim plugin.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_axis_loop.cpp THREADS hsa_daemon_axis hsa_test_counting_allocator)
target_compile_definitions(daemon_axis_loop PRIVATE HSA_PLUGIN_DIR="${HSA_PLUGIN_DIR}")
add_dependencies(daemon_axis_loop hsa_driver_sim)
# daemon/axis/input_age.hpp: the age and stale mark of an input's value.
hsa_add_gtest(daemon ${CMAKE_CURRENT_SOURCE_DIR}/test_input_age.cpp hsa_daemon_axis)

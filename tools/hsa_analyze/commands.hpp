// hsa-analyze: offline analysis for commissioning engineers. Each subcommand lives in its own
// file and registers itself on the CLI11 application here.
#pragma once

#include <CLI/CLI.hpp>

namespace hsa::analyze {

void add_calibration_command(CLI::App& app);
void add_experiment_command(CLI::App& app);
void add_identify_command(CLI::App& app);
void add_identify_valve_command(CLI::App& app);
void add_loop_command(CLI::App& app);
void add_predictor_command(CLI::App& app);
void add_tune_command(CLI::App& app);
void add_valve_law_command(CLI::App& app);

}  // namespace hsa::analyze

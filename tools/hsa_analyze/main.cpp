#include <CLI/CLI.hpp>

#include "tools/hsa_analyze/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hsa-analyze: check the rig model and the loop gains before a rig ever moves"};
  app.require_subcommand(1);
  hsa::analyze::add_calibration_command(app);
  hsa::analyze::add_experiment_command(app);
  hsa::analyze::add_identify_command(app);
  hsa::analyze::add_identify_valve_command(app);
  hsa::analyze::add_loop_command(app);
  hsa::analyze::add_predictor_command(app);
  hsa::analyze::add_tune_command(app);
  hsa::analyze::add_valve_law_command(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}

// What one valve-loop sample costs the RT thread, per law of docs/valve-loop.md, in closed loop
// with the simulated proportional valve (the rig's step is not timed): the 50 % square wave at
// 10 Hz, whose jumps start the time-optimal step's moves, and the 70 % triangle. Each sample's
// predictor update + law update (+ the model predictor's commanded()), or the predictive law's
// update with its QP, is timed on its own with
// the steady clock; the clock's own cost, measured first, is printed beside the figures.
//
//   bench_valve_loop [--periods N]
//
// Prints per law and reference: samples, p50, p99, p99.9 and max ns, and for the time-optimal
// law the same over the samples inside a move. A benchmark, never asserted by a test.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "control/state_predictor.hpp"
#include "control/valve_law.hpp"
#include "control/valve_model_predictor.hpp"
#include "control/valve_predictive_design.hpp"
#include "sim/rig.hpp"

namespace {

using namespace hsa;
using Clock = std::chrono::steady_clock;

// The paper's valve as identified_valve() gives it from the default valve-excite record
// (hsa-analyze identify-valve): the laws' settings, without running the identification here.
control::IdentifiedValve identified() {
  return {.gain_m_per_a = 1.8237e-3, .rest_position_m = -2.49997e-3, .natural_frequency_hz = 49.994,
          .damping_ratio = 0.29972, .magnetic_lag_s = 1.50625e-3, .width_a = 0.29999, .delay_s = 0.5e-3,
          .current_max_a = 3.0};
}

struct Figures {
  std::vector<double> all, in_move;
  std::vector<double> qp_iterations, bound_commands;  // the predictive law's, per sample
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

template <class Reference>
Figures run(const control::ValveLawParams& law_params, int periods, Reference reference) {
  sim::RigConfig c;
  c.valve = sim::ValveKind::proportional;
  sim::Rig rig(c);
  control::StatePredictor paper(control::predictor_gains(control::kTable2Gamma), law_params.period_s);
  std::optional<control::ValveModelPredictor> model;
  if (law_params.model_predictor.enabled) model.emplace(law_params.model_predictor, law_params.period_s);
  control::ValveLaw law(law_params);
  std::optional<control::ValvePredictiveLaw> predictive;
  if (law_params.predictive.enabled) predictive.emplace(law_params.predictive);
  const double y0 = rig.read().spool_lvdt_m.value;
  paper.reset(y0);
  if (model) model->reset(y0);
  Figures f;
  const long n = static_cast<long>(periods) * 1000;
  f.all.reserve(static_cast<std::size_t>(n));
  f.in_move.reserve(static_cast<std::size_t>(n));
  for (long k = 0; k < n; ++k) {
    const double r = reference(static_cast<double>(k) * law_params.period_s);
    const double y = rig.read().spool_lvdt_m.value;
    double command = 0.0;
    const auto t0 = Clock::now();
    if (predictive) {
      command = predictive->update(r, y);
    } else {
      const control::PredictorOutput p = model ? model->update(y) : paper.update(y);
      command = law.update(r, p);
      if (model) model->commanded(command);
    }
    const auto t1 = Clock::now();
    const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
    if (k >= 1000) {  // after the first period
      f.all.push_back(ns);
      if (predictive) {
        f.qp_iterations.push_back(predictive->last_qp_iterations());
        f.bound_commands.push_back(predictive->last_active_commands());
      }
      if (law.time_optimal().mode() != control::ValveTimeOptimal::Mode::track) f.in_move.push_back(ns);
    }
    rig.set_valve_command(command);
    rig.step();
  }
  return f;
}

void print(const char* law, const char* reference, const std::vector<double>& v) {
  std::printf("%-16s %-22s %8zu %8.0f %8.0f %8.0f %8.0f\n", law, reference, v.size(), percentile(v, 0.5),
              percentile(v, 0.99), percentile(v, 0.999), v.empty() ? NAN : *std::max_element(v.begin(), v.end()));
}

}  // namespace

int main(int argc, char** argv) {
  int periods = 40;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--periods") == 0 && i + 1 < argc) {
      periods = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--periods N]  (N reference periods of 0.1 s, default 40)\n", argv[0]);
      return 2;
    }
  }
  if (periods < 2) {
    std::fprintf(stderr, "bench_valve_loop: --periods must be at least 2\n");
    return 2;
  }
  std::vector<double> clock;
  for (int i = 0; i < 100000; ++i) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    clock.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
  }
  std::printf("valve loop sample (predictor + law), ns; the clock pair alone: p50 %.0f, p99 %.0f ns\n",
              percentile(clock, 0.5), percentile(clock, 0.99));
  std::printf("%-16s %-22s %8s %8s %8s %8s %8s\n", "law", "reference", "samples", "p50", "p99", "p99.9", "max");
  const double a_sq = 0.5 * 1.25e-3, a_tri = 0.7 * 1.25e-3;
  const auto square = [&](double t) { return std::fmod(t * 10.0, 1.0) < 0.5 ? a_sq : -a_sq; };
  const auto triangle = [&](double t) {
    const double p = std::fmod(t * 10.0, 1.0);
    return a_tri * (p < 0.25 ? 4.0 * p : p < 0.75 ? 2.0 - 4.0 * p : 4.0 * p - 4.0);
  };
  const control::IdentifiedValve v = identified();
  const struct {
    const char* name;
    control::ValveLawStep step;
  } laws[] = {{"model-inverse", control::ValveLawStep::model_inverse},
              {"model-predictor", control::ValveLawStep::model_predictor},
              {"time-optimal", control::ValveLawStep::time_optimal}};
  print("preset", "triangle 70 %, 10 Hz", run(control::simulated_proportional_valve_law(), periods, triangle).all);
  for (const auto& l : laws) {
    const control::ValveLawParams p = control::identified_valve_law(v, l.step);
    print(l.name, "triangle 70 %, 10 Hz", run(p, periods, triangle).all);
    const Figures sq = run(p, periods, square);
    print(l.name, "square 50 %, 10 Hz", sq.all);
    if (l.step == control::ValveLawStep::time_optimal) print(l.name, "  samples in a move", sq.in_move);
  }
  // The predictive law with the settings its design picks on the paper's valve (docs/valve-loop.md),
  // on the fit's model of that valve (identification::ValveModel's defaults are its figures).
  control::ValveLawParams predictive = control::identified_valve_law(v, control::ValveLawStep::spring_inverse);
  control::ValvePredictiveSettings settings;
  settings.preview_samples = 28;
  settings.rate_weight_m2_per_a2 = 2e-11;
  settings.dither_fraction = 0.75;
  settings.disturbance_walk_a = 1e-6;
  settings.headroom_fraction = 0.5;
  control::ValvePredictiveValve valve;
  valve.regulator_delay_s = 2e-4;
  valve.current_max_a = 3.0;
  predictive.predictive =
      control::valve_predictive_params(valve, predictive.period_s, predictive.dither_frequency_hz, settings);
  const Figures tri = run(predictive, periods, triangle);
  print("predictive", "triangle 70 %, 10 Hz", tri.all);
  const Figures sq = run(predictive, periods, square);
  print("predictive", "square 50 %, 10 Hz", sq.all);
  std::printf("\npredictive law's QP (H = %d commands): iterations and commands at a bound, per sample\n",
              predictive.predictive.horizon_samples);
  std::printf("%-22s %-12s %8s %8s %8s %8s\n", "reference", "", "p50", "p99", "p99.9", "max");
  for (const auto& [name, f] : {std::pair<const char*, const Figures*>{"triangle 70 %, 10 Hz", &tri},
                                {"square 50 %, 10 Hz", &sq}}) {
    for (const auto& [what, v] : {std::pair<const char*, const std::vector<double>*>{"iterations", &f->qp_iterations},
                                  {"bound", &f->bound_commands}})
      std::printf("%-22s %-12s %8.0f %8.0f %8.0f %8.0f\n", name, what, percentile(*v, 0.5), percentile(*v, 0.99),
                  percentile(*v, 0.999), *std::max_element(v->begin(), v->end()));
  }
  return 0;
}

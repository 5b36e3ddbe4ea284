// hsa-analyze predictor: gains and frequency response of the valve loop's state predictor
// (Canuto et al. 2014, eqs 18–23).
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "control/predictor_analysis.hpp"
#include "tools/hsa_analyze/commands.hpp"

namespace hsa::analyze {

namespace {

// One object; numbers that are not finite are written as null, the JSON library's rule.
void print_json(const std::array<double, 4>& gamma, double period_s, const control::PredictorAnalysis& a) {
  nlohmann::ordered_json eigenvalues = nlohmann::ordered_json::array();
  for (const auto& e : a.eigenvalues) eigenvalues.push_back({e.real(), e.imag()});
  const nlohmann::ordered_json o = {
      {"gamma", gamma},
      {"period_s", period_s},
      {"coefficients", {{"c3", a.coefficients.c3}, {"c2", a.coefficients.c2}, {"c1", a.coefficients.c1},
                        {"c0", a.coefficients.c0}}},
      {"gains", {{"beta", a.gains.beta}, {"l_a", a.gains.l_a}, {"l_d", a.gains.l_d}, {"m_a", a.gains.m_a},
                 {"m_d", a.gains.m_d}}},
      {"eigenvalues", std::move(eigenvalues)},
      {"peak_magnitude", a.peak_magnitude},
      {"peak_hz", a.peak_hz},
      {"minus_3db_hz", a.minus_3db_hz}};
  std::printf("%s\n", o.dump().c_str());
}

void print_text(const std::array<double, 4>& gamma, double period_s, const control::PredictorAnalysis& a) {
  std::printf("state predictor, gamma = {%g, %g, %g, %g}, T = %g s (Nyquist %g Hz)\n", gamma[0], gamma[1],
              gamma[2], gamma[3], period_s, 0.5 / period_s);
  std::printf("  coefficients (eq 18)  c3 = %.6g, c2 = %.6g, c1 = %.6g, c0 = %.6g\n", a.coefficients.c3,
              a.coefficients.c2, a.coefficients.c1, a.coefficients.c0);
  std::printf("  gains (eqs 19-21)     beta = %.6g, l_a = %.6g, l_d = %.6g, m_a = %.6g, m_d = %.6g\n",
              a.gains.beta, a.gains.l_a, a.gains.l_d, a.gains.m_a, a.gains.m_d);
  std::printf("  eigenvalues of A      ");
  for (std::size_t k = 0; k < a.eigenvalues.size(); ++k) {
    // Double eigenvalues come out split by ~1e-8 (Jordan blocks); 6 digits hide that.
    std::printf("%.6g%s", a.eigenvalues[k].real(), k + 1 < a.eigenvalues.size() ? ", " : "\n");
  }
  std::printf("  V_px peak (eq 23)     %.4f (%.2f dB) at %.1f Hz\n", a.peak_magnitude,
              20.0 * std::log10(a.peak_magnitude), a.peak_hz);
  if (std::isfinite(a.minus_3db_hz)) std::printf("  V_px -3 dB            %.1f Hz\n", a.minus_3db_hz);
  else std::printf("  V_px -3 dB            not reached below Nyquist\n");
}

}  // namespace

void add_predictor_command(CLI::App& app) {
  struct Options {
    std::vector<double> gamma{control::kTable2Gamma.begin(), control::kTable2Gamma.end()};
    double period_s = 1e-4;
    double l_d = 0.0;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "predictor", "state predictor of the valve loop: gains, eigenvalues, position transfer V_px");
  cmd->add_option("--gamma", options->gamma,
                  "the four complementary eigenvalues, each in (0, 1], comma separated (Table 2: 0.4,0.4,0.04,0.04)")
      ->delimiter(',')
      ->expected(4)
      ->capture_default_str();
  cmd->add_option("--period", options->period_s, "sample period T in seconds")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--ld", options->l_d, "the free gain l_d (eq 21); transfer functions do not depend on it")
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "print one JSON object");
  cmd->callback([options] {
    if (options->gamma.size() != 4)
      throw CLI::ValidationError("--gamma", "expected four values, got " + std::to_string(options->gamma.size()));
    const std::array<double, 4> gamma{options->gamma[0], options->gamma[1], options->gamma[2], options->gamma[3]};
    control::PredictorAnalysis a;
    try {
      a = control::analyze_predictor(gamma, options->period_s, options->l_d);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("predictor", e.what());
    }
    if (options->json) print_json(gamma, options->period_s, a); else print_text(gamma, options->period_s, a);
  });
}

}  // namespace hsa::analyze

// diagnosis.json and extended.yaml (schema: docs/diagnose.md).
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "rpem/analysis/diagnose/diagnose_output.hpp"

namespace rpem::analysis {
namespace {

nlohmann::json params_json(const std::vector<NamedValue>& values) {
  nlohmann::json p = nlohmann::json::object();
  for (const NamedValue& v : values) p[v.name] = v.text.empty() ? nlohmann::json(v.value) : nlohmann::json(v.text);
  return p;
}

nlohmann::json summary_json(const EstimateSummary& s) {
  nlohmann::json j;
  j["psi_m_Wb"] = s.psi_m_Wb;
  j["r_s_Ohm"] = s.r_s_Ohm;
  j["psi_m_error_pct"] = s.psi_m_error_pct ? nlohmann::json(*s.psi_m_error_pct) : nlohmann::json(nullptr);
  j["r_s_error_pct"] = s.r_s_error_pct ? nlohmann::json(*s.r_s_error_pct) : nlohmann::json(nullptr);
  return j;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  if (!f || !(f << text)) throw std::runtime_error("cannot write " + path);
}

}  // namespace

std::vector<NamedValue> found_parameters(const Diagnosis& d, std::size_t j) {
  return describe(d.selection.model.effects[j], d.selection.model.parameters[j].data(), d.context);
}

void write_diagnosis_json(const std::string& path, const Diagnosis& d, const std::string& config_path) {
  const LogData& log = *d.log;
  const Selection& s = d.selection;
  nlohmann::json out;
  std::size_t used = 0;
  for (bool u : log.used) used += u;
  out["log"] = {{"path", log.path},
                {"model", to_string(log.mode)},
                {"kind", log.averaged ? "averaged" : "phase_samples"},
                {"samples", log.rows.size()},
                {"samples_used", used},
                {"excluded_idle", log.excluded_idle},
                {"excluded_transitional", log.excluded_transitional},
                {"duration_s", log.t_end_s - log.t_start_s},
                {"median_sample_interval_s", log.median_dt_s}};
  out["machine_config"] = config_path;

  out["effects"] = nlohmann::json::array();
  for (std::size_t j = 0; j < s.found.size(); ++j) {
    const FoundEffect& f = s.found[j];
    out["effects"].push_back({{"name", f.effect.name()},
                              {"params", params_json(found_parameters(d, j))},
                              {"heldout_rms_before", f.heldout_rms_before_A},
                              {"heldout_rms_after", f.heldout_rms_after_A},
                              {"gain_pct", f.gain_pct},
                              {"p_value", f.p_value}});
  }
  const double gain = s.nominal_heldout_rms_A > 0.0 ? 100.0 * (1.0 - s.extended_heldout_rms_A / s.nominal_heldout_rms_A) : 0.0;
  out["nominal"] = {{"heldout_rms", s.nominal_heldout_rms_A},
                    {"rms", d.statistics.rms_A.before},
                    {"estimates", summary_json(d.estimates.nominal_summary)}};
  out["extended"] = {{"heldout_rms", s.extended_heldout_rms_A},
                     {"rms", d.statistics.rms_A.after},
                     {"gain_pct", gain},
                     {"estimates", summary_json(d.estimates.extended_summary)}};
  out["estimates_method"] = d.estimates.method;
  out["not_identifiable"] = nlohmann::json::array();
  for (const Unidentifiable& u : s.not_identifiable) out["not_identifiable"].push_back({{"effects", u.effects}, {"reason", u.reason}});

  out["selection"] = nlohmann::json::array();
  for (const auto& round : s.rounds) {
    nlohmann::json r = nlohmann::json::array();
    for (const CandidateScore& c : round) {
      nlohmann::json cj = {{"effect", c.effect.label()}, {"screen_ssr_A2", c.screen_ssr}, {"fitted", c.fitted}};
      if (c.fitted) {
        cj["gain_pct"] = c.gain_pct;
        cj["p_value"] = c.p_value;
        cj["heldout_block_log_ratios"] = c.block_log_ratio;
      }
      r.push_back(cj);
    }
    out["selection"].push_back(r);
  }
  out["options"] = {{"min_gain_pct", d.options.selection.min_gain_pct},
                    {"max_p", d.options.selection.max_p},
                    {"reference_C", d.context.reference_C},
                    {"switching_frequency_Hz", d.context.switching_frequency_Hz},
                    {"blocks", log.blocks}};
  out["elapsed_s"] = d.elapsed_s;
  write_text(path, out.dump(2) + "\n");
}

void write_extended_yaml(const std::string& path, const Diagnosis& d, const std::string& config_text) {
  std::string header = "# Written by rpem diagnose: " + d.log->path + " diagnosed with this configuration; the\n"
                       "# model_extensions section holds the effects found (docs/diagnose.md, docs/model-extensions.md).\n";
  if (d.selection.found.empty()) header += "# No effect was found: the model is the input's.\n";
  write_text(path, header + io::replace_model_extensions(config_text, io::model_extensions_yaml(d.extended_config)));
}

}  // namespace rpem::analysis

#include "report/material_library.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/radiometry.h"
#include "core/subprocess.h"
#include "reconstruct/merl_table.h"
#include "report/report_png.h"
#include "report/report_script.h"
#include "report/sphere_render.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string Absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

// The JSON value at a path of keys, or null when any of them is absent.
nlohmann::json At(const nlohmann::json& value, std::initializer_list<const char*> keys) {
  const nlohmann::json* node = &value;
  for (const char* key : keys) {
    if (!node->is_object() || !node->contains(key)) return nullptr;
    node = &(*node)[key];
  }
  return *node;
}

// `path` is inside `folder` (or is it).
bool Inside(const std::string& path, const std::string& folder) {
  const fs::path p = fs::weakly_canonical(path), f = fs::weakly_canonical(folder);
  auto mismatch = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return mismatch.first == f.end();
}

// The lines of the log that carry an ibrdf error ("ibrdf: error: ..."), without the prefix, and the
// last non-empty line.
struct LogErrors {
  std::vector<std::string> errors;
  std::string last_line;
};
LogErrors ReadLogErrors(const std::string& path) {
  LogErrors result;
  std::ifstream in(path);
  std::string line;
  const std::string prefix = "ibrdf: error: ";
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t at = line.rfind('\r');  // progress bars overwrite themselves
    if (at != std::string::npos) line = line.substr(at + 1);
    if (line.empty()) continue;
    result.last_line = line;
    const size_t found = line.find(prefix);
    if (found != std::string::npos) result.errors.push_back(line.substr(found + prefix.size()));
    if (line.rfind("ibrdf: bug: ", 0) == 0) result.errors.push_back(line);
  }
  return result;
}

int64_t MTime(const std::string& path) {
  std::error_code error;
  const auto time = fs::last_write_time(path, error);
  return error ? -1 : int64_t(time.time_since_epoch().count());
}

// Hard-links `from` to `to` (same file system: no copy of a 35 MB table), else copies it.
void Place(const fs::path& from, const fs::path& to) {
  std::error_code error;
  fs::create_hard_link(from, to, error);
  if (error) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

void PlaceTree(const fs::path& from, const fs::path& to) {
  fs::create_directories(to);
  for (const fs::directory_entry& item : fs::directory_iterator(from)) {
    const std::string name = item.path().filename().string();
    if (name.rfind(".", 0) == 0) continue;  // temporaries of a writer
    if (item.is_directory()) {
      PlaceTree(item.path(), to / name);
    } else if (item.is_regular_file()) {
      Place(item.path(), to / name);
    }
  }
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Percent(const nlohmann::json& fraction) {
  if (!fraction.is_number()) return "";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f %%", 100.0 * fraction.get<double>());
  return buffer;
}

// The mean of a per-channel figure, or the number itself.
nlohmann::json Overall(const nlohmann::json& value) {
  if (value.is_number()) return value;
  if (!value.is_array() || value.empty()) return nullptr;
  double sum = 0.0;
  for (const nlohmann::json& v : value) {
    if (!v.is_number()) return nullptr;
    sum += v.get<double>();
  }
  return sum / double(value.size());
}

// The lit sphere of a MERL table, at one exposure for every material (LibraryOptions).
void WriteSphere(const MerlTable& table, const LibraryOptions& options, const std::string& path) {
  const Image linear =
      RenderSphere(options.sphere_size, options.sphere_phase_deg * kDegree,
                   [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return table.Lookup(wi, wo); });
  const double scale = options.sphere_white_level * kPi;
  Image image(linear.width, linear.height, 3);
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = linear.at(x, y, std::min(c, linear.channels - 1));
        // No value in the table: a grey the legend names.
        image.at(x, y, c) = std::isfinite(v) ? float(LinearToSrgb(std::clamp(v * scale, 0.0, 1.0))) : 0.35f;
      }
    }
  }
  WriteReportPng(path, image);
}

// The table along the incidence plane at `theta_i_deg`: the exitance angle signed (positive on the
// light's side), RGB, null where the table has no value.
nlohmann::json IncidencePlane(const MerlTable& table, double theta_i_deg) {
  nlohmann::json angles = nlohmann::json::array(), rgb = nlohmann::json::array();
  const Eigen::Vector3d wi(std::sin(theta_i_deg * kDegree), 0.0, std::cos(theta_i_deg * kDegree));
  for (int t = -88; t <= 88; ++t) {
    const Eigen::Vector3d wo(std::sin(t * kDegree), 0.0, std::cos(t * kDegree));
    const Eigen::Vector3d f = table.Lookup(wi, wo);
    angles.push_back(t);
    if (f.minCoeff() < 0.0) {
      rgb.push_back(nullptr);
    } else {
      rgb.push_back({f.x(), f.y(), f.z()});
    }
  }
  return {{"theta_i_deg", theta_i_deg}, {"theta_o_deg", angles}, {"rgb", rgb}};
}

// The comparison plot (matplotlib, Debian's python3): one panel per incidence angle, the luminance
// of each material's table in the incidence plane, log scale.
const char* kPlotScript = R"PY(
import json, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
data = json.load(open(sys.argv[1]))
angles = data["theta_i_deg"]
fig, axes = plt.subplots(1, len(angles), figsize=(5.2 * len(angles), 4.0), squeeze=False)
for ax, theta_i in zip(axes[0], angles):
    for m in data["materials"]:
        curve = next(c for c in m["curves"] if c["theta_i_deg"] == theta_i)
        xs, ys = [], []
        for x, v in zip(curve["theta_o_deg"], curve["rgb"]):
            xs.append(x)
            ys.append(float("nan") if v is None else 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2])
        ax.plot(xs, ys, label=m["name"])
    ax.axvline(theta_i, color="0.7", lw=0.8, ls="--")
    ax.axvline(-theta_i, color="0.7", lw=0.8, ls=":")
    ax.set_yscale("log")
    ax.set_xlim(-90, 90)
    ax.set_title("incidence plane, theta_i = %g deg" % theta_i)
    ax.set_xlabel("exitance angle, deg (+: light's side, dashed; -: mirror side, dotted)")
    ax.set_ylabel("BRDF luminance, 1/sr")
    ax.grid(True, which="both", alpha=0.3)
axes[0][-1].legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=90)
)PY";

struct Collected {
  nlohmann::json record;
  std::optional<MerlTable> table;
};

// Places the run's files under materials/NAME/ in `tmp`; adds their names (relative to the library)
// to record["files"], and the absent ones to record["absent"].
void CollectFiles(const LibraryEntry& entry, const fs::path& tmp, const LibraryOptions& options, Collected* c) {
  nlohmann::json& record = c->record;
  const std::string name = entry.name;
  const fs::path folder = tmp / "materials" / name;
  fs::create_directories(folder);
  const std::string rel = "materials/" + name + "/";
  nlohmann::json files = nlohmann::json::object();
  nlohmann::json absent = nlohmann::json::array();
  const fs::path run = entry.run_dir;
  const fs::path reconstruction = run / "reconstruction";

  const fs::path merl = reconstruction / "brdf.binary";
  if (fs::is_regular_file(merl)) {
    Place(merl, folder / (name + ".binary"));
    files["merl"] = rel + name + ".binary";
    try {
      c->table = ReadMerl(merl.string());
      WriteSphere(*c->table, options, (folder / (name + ".sphere.png")).string());
      files["sphere"] = rel + name + ".sphere.png";
    } catch (const Error& error) {
      record["warnings"].push_back(std::string("MERL table unreadable: ") + error.what());
    }
  } else {
    absent.push_back("merl");
  }
  // Fits (material files), renderer snippets, RGL .bsdf tables and the domain map: whatever the
  // reconstruction holds, under the material's name.
  nlohmann::json fits = nlohmann::json::array(), snippets = nlohmann::json::array(), bsdf = nlohmann::json::array();
  std::vector<fs::path> items;
  if (fs::is_directory(reconstruction)) {
    for (const fs::directory_entry& item : fs::directory_iterator(reconstruction)) {
      if (item.is_regular_file()) items.push_back(item.path());
    }
  }
  std::sort(items.begin(), items.end());
  int bsdf_count = 0;
  for (const fs::path& item : items) bsdf_count += item.extension() == ".bsdf";
  for (const fs::path& item : items) {
    const std::string file = item.filename().string();
    const std::string ext = item.extension().string();
    if (file.rfind(".", 0) == 0) continue;
    std::string target;
    nlohmann::json* list = nullptr;
    if (file == "brdf.json") {  // the table's sidecar (its domain classes and any fill), not a fit
      files["table_sidecar"] = rel + name + ".brdf.json";
      Place(item, folder / (name + ".brdf.json"));
      continue;
    }
    if (ext == ".json" && file != "summary.json") {
      list = &fits;
    } else if (ext == ".pbrt" || ext == ".xml") {
      list = &snippets;
    } else if (ext == ".bsdf") {
      list = &bsdf;
      if (bsdf_count == 1) target = name + ".bsdf";
    } else if (file == "domain.npy") {
      files["domain"] = rel + name + ".domain.npy";
      Place(item, folder / (name + ".domain.npy"));
      continue;
    } else {
      continue;  // brdf.npy and effective_samples.npy: the run folder keeps them
    }
    if (target.empty()) target = name + "." + file;
    Place(item, folder / target);
    list->push_back(rel + target);
  }
  files["fits"] = fits;
  files["snippets"] = snippets;
  files["bsdf"] = bsdf;
  if (fits.empty()) absent.push_back("fits");
  if (snippets.empty()) absent.push_back("snippets");
  if (bsdf.empty()) absent.push_back("bsdf");
  if (!fs::exists(reconstruction / "domain.npy")) absent.push_back("domain");

  if (fs::is_regular_file(run / "report" / "index.html")) {
    PlaceTree(run / "report", folder / "report");
    files["report"] = rel + "report/index.html";
  } else {
    absent.push_back("report");
  }
  if (fs::is_regular_file(run / "summary.json")) {
    Place(run / "summary.json", folder / (name + ".summary.json"));
    files["summary"] = rel + name + ".summary.json";
  }
  record["files"] = files;
  record["absent"] = absent;
}

std::string Card(const nlohmann::json& r) {
  std::ostringstream html;
  const std::string status = r.at("status").get<std::string>();
  const nlohmann::json files = r.value("files", nlohmann::json::object());
  html << "<div class=\"card " << status << "\">\n<h2>" << HtmlEscape(r.at("name").get<std::string>()) << "</h2>\n";
  if (files.contains("sphere")) {
    html << "<img src=\"" << files["sphere"].get<std::string>() << "\" alt=\"lit sphere\">\n";
  }
  if (status != "ok") {
    html << "<p class=\"status\">" << status << "</p>\n<pre>" << HtmlEscape(r.value("error", std::string()))
         << "</pre>\n";
    if (files.contains("log")) html << "<p><a href=\"" << files["log"].get<std::string>() << "\">log</a></p>\n";
  }
  html << "<table>\n";
  auto row = [&](const std::string& label, const std::string& value) {
    if (!value.empty()) html << "<tr><th>" << label << "</th><td>" << HtmlEscape(value) << "</td></tr>\n";
  };
  const nlohmann::json f = r.value("figures", nlohmann::json::object());
  if (f.value("samples", nlohmann::json()).is_number()) row("samples", std::to_string(f["samples"].get<int64_t>()));
  row("table coverage", Percent(f.value("table_coverage", nlohmann::json())));
  row("reciprocity error", Percent(f.value("reciprocity", nlohmann::json())));
  row("bilateral-symmetry error", Percent(f.value("bilateral_symmetry", nlohmann::json())));
  if (f.value("truth_spatially_varying", false)) row("truth", "spatially varying: no single-material comparison");
  row("samples vs truth (median)", Percent(f.value("samples_median_rel_error", nlohmann::json())));
  row("table vs truth (rel. RMS)", Percent(f.value("brdf_rel_rmse", nlohmann::json())));
  const nlohmann::json fits = f.contains("fits") ? f["fits"] : nlohmann::json::object();
  for (auto it = fits.begin(); it != fits.end(); ++it)
    row(it.key() + " fit vs samples (rel. RMS)", Percent(it.value()));
  const nlohmann::json total = At(r, {"timings_s", "stages_total"});
  if (total.is_number()) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.1f s", total.get<double>());
    row("stages took", buffer);
  }
  html << "</table>\n<p class=\"links\">";
  if (files.contains("report")) html << "<a href=\"" << files["report"].get<std::string>() << "\">report</a> ";
  if (files.contains("merl")) html << "<a href=\"" << files["merl"].get<std::string>() << "\">MERL table</a> ";
  for (const char* kind : {"fits", "snippets", "bsdf"}) {
    for (const nlohmann::json& file : files.value(kind, nlohmann::json::array())) {
      const std::string path = file.get<std::string>();
      html << "<a href=\"" << path << "\">" << HtmlEscape(fs::path(path).filename().string()) << "</a> ";
    }
  }
  html << "</p>\n";
  if (!r.value("absent", nlohmann::json::array()).empty()) {
    std::string list;
    for (const nlohmann::json& a : r["absent"]) list += (list.empty() ? "" : ", ") + a.get<std::string>();
    html << "<p class=\"absent\">absent: " << HtmlEscape(list) << "</p>\n";
  }
  html << "<p class=\"source\">" << HtmlEscape(r.value("source", std::string())) << "</p>\n</div>\n";
  return html.str();
}

std::string IndexHtml(const nlohmann::json& index) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>ibrdf material library</title>\n<style>\n"
          "body{font-family:sans-serif;margin:1.5em;background:#fafafa}\n"
          ".grid{display:flex;flex-wrap:wrap;gap:1em}\n"
          ".card{background:#fff;border:1px solid #ccc;border-radius:6px;padding:0.8em;width:300px}\n"
          ".card.failed{border-color:#c33;background:#fff4f4}.card.incomplete{border-color:#c93}\n"
          ".card img{display:block;margin:auto;background:#000}\n"
          ".card h2{font-size:1.1em;margin:0 0 0.4em}.card table{font-size:0.85em;width:100%}\n"
          ".card th{text-align:left;font-weight:normal;color:#555}.card td{text-align:right}\n"
          ".status{color:#c33;font-weight:bold}pre{white-space:pre-wrap;font-size:0.8em}\n"
          ".absent,.source{font-size:0.75em;color:#777;word-break:break-all}\n</style></head><body>\n";
  const nlohmann::json& counts = index.at("counts");
  html << "<h1>Material library</h1>\n<p>" << counts.at("ok").get<int>() << " materials, "
       << counts.at("failed").get<int>() << " failed, " << counts.at("incomplete").get<int>()
       << " incomplete. Spheres: one exposure for every material (a white Lambertian disc facing the "
          "light at "
       << int(std::lround(100 * index.at("sphere").at("white_level").get<double>())) << " % of full scale), light "
       << index.at("sphere").at("phase_deg").get<double>()
       << " degrees from the view; grey: no value in the table. Data: <a href=\"index.json\">index.json</a>.</p>\n";
  if (index.contains("comparison") && index["comparison"].contains("plot")) {
    html << "<h2>Comparison in the incidence plane</h2>\n<img src=\"" << index["comparison"]["plot"].get<std::string>()
         << "\" alt=\"comparison\">\n";
  }
  html << "<div class=\"grid\">\n";
  for (const nlohmann::json& r : index.at("materials")) html << Card(r);
  html << "</div>\n</body></html>\n";
  return html.str();
}

}  // namespace

bool LibraryOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!out_dir.empty());
  IBRDF_CHECK_OPTION_GE(sphere_size, 16);
  IBRDF_CHECK_OPTION(sphere_phase_deg >= 0.0 && sphere_phase_deg < 90.0);
  IBRDF_CHECK_OPTION(sphere_white_level > 0.0);
  return true;
}

std::string LibraryResult::BriefReport() const {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.2f s", seconds);
  return std::to_string(materials) + " materials, " + std::to_string(failed) + " failed, " +
         std::to_string(incomplete) + " incomplete: " + index_html + " (" + buffer + ")";
}

nlohmann::json LibraryRecord(const LibraryEntry& entry) {
  nlohmann::json record = {{"name", entry.name}, {"run_dir", Absolute(entry.run_dir)}};
  const std::string summary_path = (fs::path(entry.run_dir) / "summary.json").string();
  const bool has_summary = fs::is_regular_file(summary_path);
  LogErrors log;
  if (!entry.log_path.empty()) {
    record["log"] = Absolute(entry.log_path);
    if (fs::is_regular_file(entry.log_path)) log = ReadLogErrors(entry.log_path);
  }
  record["source"] = entry.source;
  // A log whose run failed after the summary was written (or with no summary) is the run's state.
  if (!log.errors.empty() && (!has_summary || MTime(entry.log_path) >= MTime(summary_path))) {
    record["status"] = "failed";
    record["error"] = log.errors.front();
    record["errors"] = log.errors;
    return record;
  }
  if (!has_summary) {
    record["status"] = "incomplete";
    record["error"] = "no summary.json: the run has not completed" +
                      (log.last_line.empty() ? std::string() : " (its log ends: " + log.last_line + ")");
    return record;
  }
  nlohmann::json summary;
  try {
    summary = ReadJsonFile(summary_path);
  } catch (const Error& error) {
    record["status"] = "failed";
    record["error"] = error.what();
    return record;
  }
  record["status"] = "ok";
  if (entry.source.empty()) record["source"] = At(summary, {"input"});
  record["session"] = At(summary, {"session"});
  record["session_name"] = At(summary, {"session_name"});
  nlohmann::json figures;
  figures["samples"] = At(summary, {"samples", "accepted"});
  figures["photos"] = At(summary, {"samples", "photos"});
  // The table's classes (measured / interpolated / unmeasured); older runs said "unsupported".
  const nlohmann::json measured = At(summary, {"reconstruction", "table", "cells_measured"});
  const nlohmann::json interpolated = At(summary, {"reconstruction", "table", "cells_interpolated"});
  nlohmann::json unmeasured = At(summary, {"reconstruction", "table", "cells_unmeasured"});
  if (unmeasured.is_null()) unmeasured = At(summary, {"reconstruction", "table", "cells_unsupported"});
  figures["table_cells_measured"] = measured;
  figures["table_cells_interpolated"] = interpolated;
  figures["table_cells_unmeasured"] = unmeasured;
  figures["table_coverage"] = nullptr;
  if (measured.is_number() && unmeasured.is_number()) {
    const double inside = measured.get<double>() + (interpolated.is_number() ? interpolated.get<double>() : 0.0);
    if (inside + unmeasured.get<double>() > 0) figures["table_coverage"] = inside / (inside + unmeasured.get<double>());
  }
  figures["reciprocity"] = At(summary, {"consistency", "reciprocity"});
  nlohmann::json symmetry = At(summary, {"consistency", "bilateral_symmetry"});
  figures["bilateral_symmetry"] = symmetry.is_null() ? At(summary, {"consistency", "isotropy"}) : symmetry;
  figures["truth_coverage"] = At(summary, {"truth", "brdf_coverage"});
  // A material map's truth (summary.json truth.spatially_varying): no figures against one material.
  figures["truth_spatially_varying"] = At(summary, {"truth", "spatially_varying"}).is_boolean() &&
                                       At(summary, {"truth", "spatially_varying"}).get<bool>();
  figures["samples_median_rel_error"] = Overall(At(summary, {"truth", "samples_median_rel_error"}));
  figures["brdf_rel_rmse"] = At(summary, {"truth", "brdf_rel_rmse_all"});
  nlohmann::json fits = nlohmann::json::object();
  const nlohmann::json fit_blocks = At(summary, {"reconstruction", "fits"});
  if (fit_blocks.is_object()) {
    for (auto it = fit_blocks.begin(); it != fit_blocks.end(); ++it) {
      const nlohmann::json error = At(it.value(), {"rel_rms_vs_samples"});
      if (error.is_number()) fits[it.key()] = error;
    }
  }
  figures["fits"] = fits;
  record["figures"] = figures;
  record["timings_s"] = At(summary, {"timings_s"});
  return record;
}

std::vector<LibraryEntry> LibraryEntriesOfRuns(const std::vector<std::string>& run_dirs) {
  std::vector<LibraryEntry> entries;
  for (const std::string& run : run_dirs) {
    if (!fs::is_directory(run)) ThrowError(run, "is not a folder (expected an `ibrdf run` folder)");
    // A session (or recipe) folder has no run's outputs: it would be a card that says only "no summary".
    const fs::path dir(run);
    const bool run_outputs = fs::exists(dir / "summary.json") || fs::exists(dir / "reconstruction");
    const std::pair<const char*, const char*> kInputs[] = {{"session.json", "session"}, {"recipe.json", "recipe"}};
    for (const auto& [manifest, kind] : kInputs) {
      if (!run_outputs && fs::is_regular_file(dir / manifest)) {
        ThrowError(run, std::string("is a ") + kind + " folder (it holds " + manifest +
                            "), not an `ibrdf run` folder: run `ibrdf run " + run +
                            " --out RUN_DIR` first and give the library RUN_DIR");
      }
    }
    entries.push_back({fs::absolute(run).lexically_normal().filename().string(), run, "", ""});
  }
  return entries;
}

LibraryResult BuildLibrary(const std::vector<LibraryEntry>& entries, const LibraryOptions& options) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("library options", why);
  const std::string out = Absolute(options.out_dir);
  std::set<std::string> names;
  for (const LibraryEntry& entry : entries) {
    if (!names.insert(entry.name).second) {
      ThrowError(entry.run_dir, "a second run named \"" + entry.name + "\" in the library");
    }
    if (Inside(out, entry.run_dir) || Inside(entry.run_dir, out)) {
      ThrowError(out, "the library folder and the run folder " + entry.run_dir +
                          " contain one another; the library is written as a whole and would replace it");
    }
  }
  bool replace = false;
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) ThrowError(out, "exists and is not a folder");
    nlohmann::json old;
    try {
      old = ReadJsonFile((fs::path(out) / "index.json").string());
    } catch (const Error&) {
    }
    const bool library = old.is_object() && old.value("format", "") == "ibrdf-library";
    if (!library && !options.overwrite) {
      ThrowError(out,
                 "exists and is not an ibrdf library (no index.json of format ibrdf-library); "
                 "--overwrite replaces it");
    }
    replace = true;
  }
  fs::create_directories(fs::path(out).parent_path());
  AtomicDirectory dir(out, replace);
  const fs::path tmp = dir.temporary_path();

  LibraryResult result;
  nlohmann::json materials = nlohmann::json::array();
  std::map<std::string, MerlTable> tables;  // the compared materials'
  std::vector<std::string> compare = options.compare;
  for (const LibraryEntry& entry : entries) {
    Collected c;
    c.record = LibraryRecord(entry);
    const std::string status = c.record["status"];
    if (status == "ok") {
      CollectFiles(entry, tmp, options, &c);
      ++result.materials;
      if (options.compare.empty() && compare.size() < 8 && c.table) compare.push_back(entry.name);
    } else {
      (status == "failed" ? result.failed : result.incomplete) += 1;
      if (!entry.log_path.empty() && fs::is_regular_file(entry.log_path)) {
        fs::create_directories(tmp / "materials" / entry.name);
        fs::copy_file(entry.log_path, tmp / "materials" / entry.name / (entry.name + ".log"));
        c.record["files"] = {{"log", "materials/" + entry.name + "/" + entry.name + ".log"}};
      }
      Log(1, "library: " + entry.name + ": " + status + ": " + c.record.value("error", std::string()));
    }
    if (c.table && std::find(compare.begin(), compare.end(), entry.name) != compare.end()) {
      tables.emplace(entry.name, std::move(*c.table));
    }
    materials.push_back(c.record);
  }
  for (const std::string& name : options.compare) {
    if (!names.count(name)) ThrowError("--compare", "no material named \"" + name + "\" in the library");
  }

  nlohmann::json index = {
      {"format", "ibrdf-library"},
      {"version", 1},
      {"materials", materials},
      {"counts", {{"ok", result.materials}, {"failed", result.failed}, {"incomplete", result.incomplete}}},
      {"sphere",
       {{"size", options.sphere_size},
        {"phase_deg", options.sphere_phase_deg},
        {"white_level", options.sphere_white_level}}}};
  // The comparison plot of the selected materials that have a table.
  nlohmann::json curves = {{"theta_i_deg", {30.0, 60.0}}, {"materials", nlohmann::json::array()}};
  nlohmann::json compared = nlohmann::json::array();
  for (const std::string& name : compare) {
    const auto it = tables.find(name);
    if (it == tables.end()) continue;
    curves["materials"].push_back(
        {{"name", name}, {"curves", {IncidencePlane(it->second, 30.0), IncidencePlane(it->second, 60.0)}}});
    compared.push_back(name);
  }
  index["comparison"] = {{"materials", compared}};
  if (!compared.empty()) {
    WriteJsonFile((tmp / "comparison.json").string(), curves);
    const std::string script = (tmp / ".comparison.py").string();
    std::ofstream(script) << kPlotScript;
    const int code =
        RunSubprocess({ReportPython(), script, (tmp / "comparison.json").string(), (tmp / "comparison.png").string()});
    fs::remove(script);
    if (code != 0) ThrowError(ReportPython(), "the comparison plot failed (exit " + std::to_string(code) + ")");
    index["comparison"]["data"] = "comparison.json";
    index["comparison"]["plot"] = "comparison.png";
  }
  WriteJsonFile((tmp / "index.json").string(), index);
  {
    std::ofstream html(tmp / "index.html");
    html << IndexHtml(index);
    if (!html) ThrowError((tmp / "index.html").string(), "could not be written");
  }
  dir.Commit();
  result.success = true;
  result.index_json = (fs::path(out) / "index.json").string();
  result.index_html = (fs::path(out) / "index.html").string();
  result.seconds = timer.ElapsedSeconds();
  return result;
}

}  // namespace ibrdf

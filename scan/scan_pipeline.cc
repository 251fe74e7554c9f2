#include "scan/scan_pipeline.h"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "scan/adapters.h"
#include "scan/ply_io.h"
#include "scan/scan_io.h"

namespace ibrdf {

bool ScanOptions::Check(std::string* why) const {
  return grid.Check(why) && clean.Check(why) && normals.Check(why) && convexity.Check(why);
}

std::vector<ScanInputSpec> InputsFromConf(const std::string& conf_path, const std::vector<std::string>& files) {
  const std::vector<StanfordConfEntry> entries = ReadStanfordConf(conf_path);
  const std::filesystem::path folder = std::filesystem::path(conf_path).parent_path();
  std::vector<ScanInputSpec> inputs;
  if (files.empty()) {
    for (const StanfordConfEntry& entry : entries) {
      const std::string path = (folder / entry.name).string();
      if (std::filesystem::exists(path)) inputs.push_back({path, entry.world_from_scan});
    }
    if (inputs.empty()) ThrowError(conf_path, "none of the scans it lists exists beside it");
    return inputs;
  }
  for (const std::string& file : files) {
    const std::string name = std::filesystem::path(file).filename().string();
    const StanfordConfEntry* found = nullptr;
    for (const StanfordConfEntry& entry : entries) {
      if (std::filesystem::path(entry.name).filename().string() == name) found = &entry;
    }
    if (!found) ThrowError(conf_path, "has no 'bmesh " + name + " ...' line for input " + file);
    inputs.push_back({file, found->world_from_scan});
  }
  return inputs;
}

std::vector<ScanInputSpec> InputsFromSession(const Session& session) {
  const SampleSpec& sample = session.sample;
  if (!IsMeshSample(sample.kind)) {
    ThrowError(session.manifest_path + ": /sample/kind",
               "the sample is a " + std::string(SampleKindName(sample.kind)) + ", not a scanned mesh");
  }
  if (sample.scan_inputs.empty()) {
    ThrowError(session.manifest_path + ": /sample/scan_inputs", "the session's mesh sample has no scan_inputs");
  }
  std::vector<ScanInputSpec> inputs;
  for (const ScanInputSpec& input : sample.scan_inputs) {
    inputs.push_back({session.AbsolutePath(input.file), input.world_from_scan});
  }
  return inputs;
}

std::vector<ScanInputSpec> ResolveScanInputs(const ScanSources& sources, std::vector<std::string>* read) {
  std::vector<ScanInputSpec> inputs;
  if (!sources.session.empty()) {
    if (!sources.files.empty() || !sources.conf.empty()) {
      ThrowError("ibrdf scan", "--session takes neither scan files nor --conf");
    }
    const Session session = Session::Load(sources.session);
    inputs = InputsFromSession(session);
    read->push_back(session.manifest_path);
  } else if (!sources.conf.empty()) {
    inputs = InputsFromConf(sources.conf, sources.files);
    read->push_back(sources.conf);
  } else {
    if (sources.files.empty()) ThrowError("ibrdf scan", "no input files (give scan files, or --conf, or --session)");
    for (const std::string& path : sources.files) inputs.push_back({path, std::nullopt});
  }
  for (const ScanInputSpec& input : inputs) read->push_back(input.file);
  return inputs;
}

ScanResult RunScan(const std::vector<ScanInputSpec>& inputs, const ScanOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("scan options", why);
  if (inputs.empty()) ThrowError("scan", "no input files");
  const Timer total;
  ScanResult result;
  ScanSummary& summary = result.summary;
  ScanMesh& merged = result.mesh;
  ScanMesh unorganized;
  bool all_have_normals = true;

  {
    StageLog stage("scan: read and tessellate");
    const Timer timer;
    for (const ScanInputSpec& input : inputs) {
      ScanMesh mesh = ReadScanFile(input.file);
      ScanInputReport report;
      report.path = input.file;
      report.points = mesh.points.size();
      if (!mesh.grid.Empty()) {
        const RangeGridReport grid = TessellateRangeGrid(options.grid, &mesh);
        report.kind = "range grid";
        report.detail = grid.BriefReport();
        mesh.grid = RangeGrid();
      } else if (!mesh.faces.empty()) {
        report.kind = "mesh";
        if (OrientFacesOutward(&mesh)) report.detail = "faces flipped to point outward";
      } else {
        report.kind = "points";
      }
      report.faces = mesh.faces.size();
      Log(1, "   " + input.file + ": " + report.kind + ", " + std::to_string(report.points) + " points, " +
                 std::to_string(report.faces) + " faces" + (report.detail.empty() ? "" : "; " + report.detail));
      if (input.world_from_scan) TransformMesh(*input.world_from_scan, &mesh);
      all_have_normals &= mesh.normals.size() == mesh.points.size();
      ScanMesh& target = report.kind == "points" ? unorganized : merged;
      const int offset = static_cast<int>(target.points.size());
      target.points.insert(target.points.end(), mesh.points.begin(), mesh.points.end());
      target.normals.insert(target.normals.end(), mesh.normals.begin(), mesh.normals.end());
      for (const Eigen::Vector3i& f : mesh.faces) target.faces.push_back(f + Eigen::Vector3i::Constant(offset));
      summary.inputs.push_back(report);
    }
    summary.step_seconds.emplace_back("read and tessellate", timer.ElapsedSeconds());
  }
  if (!unorganized.points.empty()) {
    if (!options.reconstruct_points) ThrowError(inputs.front().file, "unorganized points, and reconstruction is off");
    StageLog stage("scan: reconstruct unorganized points (CGAL advancing front)");
    const Timer timer;
    unorganized.faces = scan_adapters::AdvancingFrontReconstruction(unorganized.points);
    OrientFacesOutward(&unorganized);
    summary.reconstructed_faces = unorganized.faces.size();
    Log(1, "   " + std::to_string(unorganized.points.size()) + " points -> " +
               std::to_string(unorganized.faces.size()) + " faces");
    const int offset = static_cast<int>(merged.points.size());
    merged.points.insert(merged.points.end(), unorganized.points.begin(), unorganized.points.end());
    merged.normals.insert(merged.normals.end(), unorganized.normals.begin(), unorganized.normals.end());
    for (const Eigen::Vector3i& f : unorganized.faces) merged.faces.push_back(f + Eigen::Vector3i::Constant(offset));
    summary.step_seconds.emplace_back("reconstruct", timer.ElapsedSeconds());
  }
  // File normals orient the fit only when every input had them.
  if (!all_have_normals) merged.normals.clear();

  {
    StageLog stage("scan: clean");
    summary.clean = CleanMesh(options.clean, &merged);
    Log(1, "   " + summary.clean.BriefReport());
    summary.step_seconds.emplace_back("clean", summary.clean.seconds);
  }
  if (merged.faces.empty() || merged.points.size() < 4) {
    ThrowError(inputs.front().file, "nothing is left of the scan after cleaning (" +
                                        std::to_string(merged.points.size()) + " points, no faces)");
  }
  {
    StageLog stage("scan: local-plane normals");
    summary.normals = FitLocalPlanes(merged, options.normals);
    StoreNormals(summary.normals, &merged);
    summary.normals.normals.clear();
    summary.normals.rms_m.clear();
    summary.normals.neighbours.clear();
    summary.normals.source.clear();
    Log(1, "   " + summary.normals.BriefReport());
    summary.step_seconds.emplace_back("normals", summary.normals.seconds);
  }
  {
    StageLog stage("scan: convexity");
    const Timer timer;
    summary.convexity = ReportConvexity(merged, options.convexity);
    merged.hull_distance_m.assign(summary.convexity.distance_m.begin(), summary.convexity.distance_m.end());
    summary.convexity.distance_m.clear();
    Log(1, "   " + summary.convexity.BriefReport());
    if (!summary.convexity.warning.empty()) Log(1, "   warning: " + summary.convexity.warning);
    summary.step_seconds.emplace_back("convexity", timer.ElapsedSeconds());
  }
  summary.total_s = total.ElapsedSeconds();
  summary.success = true;
  return result;
}

std::string ScanSummary::BriefReport() const {
  std::ostringstream out;
  out << std::setprecision(3) << "scan: " << inputs.size() << " input(s) -> " << clean.points_out << " points, "
      << clean.faces_out << " faces; normal RMS residual median " << normals.rms_median_m * 1e3 << " mm; "
      << 100.0 * convexity.fraction_within << " % within " << convexity.tolerance_m * 1e3 << " mm of the hull"
      << (convexity.needs_shadow_rays ? " (shadow rays needed)" : " (convex)");
  return out.str();
}

std::string ScanSummary::Table() const {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << "Scan summary\n";
  for (const ScanInputReport& input : inputs) {
    out << "  input     " << input.path << ": " << input.kind << ", " << input.points << " points, " << input.faces
        << " faces\n";
  }
  if (reconstructed_faces > 0) out << "  reconstructed (CGAL advancing front): " << reconstructed_faces << " faces\n";
  out << "  merged    " << clean.points_in << " points, " << clean.faces_in << " faces\n";
  out << "  removed   ";
  bool first = true;
  for (const auto& [step, count] : clean.removed) {
    out << (first ? "" : ", ") << step << " " << count;
    first = false;
  }
  out << "\n  result    " << clean.points_out << " points, " << clean.faces_out << " faces, " << clean.pieces
      << " piece(s)\n";
  out << "  normals   radius " << normals.radius_m * 1e3 << " mm (spacing " << normals.spacing_m * 1e3 << " mm); "
      << normals.fitted << " fitted, median " << std::setprecision(0) << normals.neighbours_median << " neighbours"
      << std::setprecision(3) << "; not fitted: " << normals.too_few_neighbours << " too few neighbours, "
      << normals.collinear << " collinear, " << normals.no_normal << " without any normal\n";
  out << "            RMS residual median " << normals.rms_median_m * 1e3 << " mm, 95th percentile "
      << normals.rms_p95_m * 1e3 << " mm\n";
  out << "  convexity " << std::setprecision(2) << 100.0 * convexity.fraction_within << " % of the surface within "
      << std::setprecision(3) << convexity.tolerance_m * 1e3 << " mm of the hull (median "
      << convexity.median_distance_m * 1e3 << " mm, max " << convexity.max_distance_m * 1e3
      << " mm): " << (convexity.needs_shadow_rays ? "NOT convex, shadow rays needed" : "convex, no shadow rays needed")
      << "\n";
  if (!convexity.warning.empty()) out << "  warning   " << convexity.warning << "\n";
  out << "  time      ";
  for (const auto& [step, seconds] : step_seconds) out << step << " " << std::setprecision(2) << seconds << " s, ";
  out << "total " << total_s << " s\n";
  return out.str();
}

nlohmann::json ScanSummary::ToJson() const {
  nlohmann::json input_list = nlohmann::json::array();
  for (const ScanInputReport& input : inputs) {
    input_list.push_back(
        {{"path", input.path}, {"kind", input.kind}, {"points", input.points}, {"faces", input.faces}});
  }
  nlohmann::json removed = nlohmann::json::object();
  for (const auto& [step, count] : clean.removed) removed[step] = count;
  nlohmann::json seconds = nlohmann::json::object();
  for (const auto& [step, s] : step_seconds) seconds[step] = s;
  seconds["total"] = total_s;
  return {{"inputs", input_list},
          {"reconstructed_faces", reconstructed_faces},
          {"points", clean.points_out},
          {"faces", clean.faces_out},
          {"pieces", clean.pieces},
          {"removed", removed},
          {"normals",
           {{"radius_m", normals.radius_m},
            {"spacing_m", normals.spacing_m},
            {"fitted", normals.fitted},
            {"too_few_neighbours", normals.too_few_neighbours},
            {"collinear", normals.collinear},
            {"without_normal", normals.no_normal},
            {"rms_median_m", normals.rms_median_m},
            {"rms_p95_m", normals.rms_p95_m},
            {"neighbours_median", normals.neighbours_median}}},
          {"convexity", convexity.ToJson()},
          {"seconds", seconds}};
}

void WriteScanOutputs(const std::string& ply_path, const ScanResult& result, const ScanOptions& options) {
  IBRDF_CHECK(result.summary.success) << "the scan stage did not run";
  nlohmann::json sidecar = result.summary.ToJson();
  sidecar["format"] = "ibrdf scan 1";
  sidecar["mesh"] = std::filesystem::path(ply_path).filename().string();
  sidecar["units"] = {{"length", "m"}};
  sidecar["vertex_properties"] = {{"x y z", "position, metres (double)"},
                                  {"nx ny nz", "unit outward local-plane normal (zero where none could be had)"},
                                  {"quality", "RMS distance of the fit's neighbours to the plane, metres"},
                                  {"fit_neighbours", "points in the fit (0: no fit; the normal is the mesh's)"},
                                  {"hull_distance", "distance to the convex hull of the sample, metres"}};
  sidecar["options"] = {{"max_edge_factor", options.grid.max_edge_factor},
                        {"max_edge_m", options.grid.max_edge_m},
                        {"remove_outliers", options.clean.remove_outliers},
                        {"outlier_neighbours", options.clean.outlier_neighbours},
                        {"outlier_stddev", options.clean.outlier_stddev},
                        {"duplicate_distance_m", options.clean.duplicate_distance_m},
                        {"tiny_face_fraction", options.clean.tiny_face_fraction},
                        {"min_piece_fraction", options.clean.min_piece_fraction},
                        {"radius_m", options.normals.radius_m},
                        {"radius_spacing_factor", options.normals.radius_spacing_factor},
                        {"min_neighbours", options.normals.min_neighbours},
                        {"hull_tolerance_m", options.convexity.tolerance_m},
                        {"hull_tolerance_fraction", options.convexity.tolerance_fraction},
                        {"min_convex_fraction", options.convexity.min_convex_fraction}};
  // The mesh and its sidecar as one unit (core/file_util.h): never a new mesh beside an old sidecar.
  AtomicFile mesh_file(ply_path), sidecar_file(ScanSidecarPath(ply_path));
  WritePly(mesh_file.temporary_path(), result.mesh);
  WriteJsonFile(sidecar_file.temporary_path(), sidecar);
  CommitWithManifest(&mesh_file, &sidecar_file);
}

}  // namespace ibrdf

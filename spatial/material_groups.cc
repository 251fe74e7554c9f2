#include "spatial/material_groups.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <unordered_map>

#include <tbb/parallel_for.h>
#include <nanoflann.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/brdf_model.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_brdf.h"
#include "core/statistics.h"
#include "core/sample_file.h"
#include "spatial/material_render.h"
#include "spatial/surface_points.h"
#include "spatial/uniformity.h"
#include "synth/material_map.h"

namespace ibrdf {
namespace {

// The grid and labels of uniformity.json: cell key -> group.
struct GroupedCells {
  double cell_m = 0.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  int groups = 0;
  std::vector<std::array<int, 2>> blend_of;  // per group ({-1, -1}: a material)
  std::vector<Eigen::Vector3d> log_centre;   // per group: log of its off-peak value (absolute)
  double max_cos_h = 1.0;                    // samples at theta_h beyond the clustering's limit are off-peak
  std::unordered_map<uint64_t, int> group_of_key;
};

// The off-peak samples' surface points and groups, searched for each sample's nearest.
struct OffPeakCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<int8_t> group;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t index, size_t dim) const { return points[index][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using OffPeakTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, OffPeakCloud>, OffPeakCloud, 3, uint32_t>;

// Every string of `value` equal to `from` becomes `to`.
void ReplaceString(nlohmann::json* value, const std::string& from, const std::string& to) {
  if (value->is_string()) {
    if (value->get<std::string>() == from) *value = to;
  } else if (value->is_structured()) {
    for (nlohmann::json& item : *value) ReplaceString(&item, from, to);
  }
}

constexpr int kOnPeak = -1;  // OffPeakGroup: no off-peak value (or a channel not measured)
constexpr int kMixed = -2;   // a value beyond `purity` of every group's centre: a mix of materials

// The group whose off-peak value is nearest the sample's (in logarithms), kMixed when that is further
// than `log_purity` in some channel, kOnPeak for a sample on the peak or with a channel not measured or
// not positive.
int OffPeakGroup(const BrdfSample& s, const GroupedCells& cells, double log_purity) {
  const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
  if (!((wi + wo).normalized().z() <= cells.max_cos_h)) return kOnPeak;
  Eigen::Vector3d value;
  for (int k = 0; k < 3; ++k) {
    if (!s.Valid(k) || !(s.brdf[k] > 0.0f)) return kOnPeak;
    value[k] = std::log(double(s.brdf[k]));
  }
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t g = 0; g < cells.log_centre.size(); ++g) {
    const double d = (value - cells.log_centre[g]).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = int(g);
    }
  }
  if (best >= 0 && (value - cells.log_centre[best]).cwiseAbs().maxCoeff() > log_purity) return kMixed;
  return best;
}

GroupedCells ReadGroupedCells(const nlohmann::json& uniformity, const std::string& path) {
  GroupedCells cells;
  if (!uniformity.contains("cell_m") || !uniformity["cell_m"].is_number() ||
      !(uniformity["cell_m"].get<double>() > 0)) {
    ThrowError(path, "has no positive \"cell_m\" (not a uniformity.json of `ibrdf uniformity`)");
  }
  cells.cell_m = uniformity["cell_m"].get<double>();
  const nlohmann::json* origin = uniformity.contains("grid_origin") ? &uniformity["grid_origin"] : nullptr;
  if (!origin || !origin->is_array() || origin->size() != 3 || !(*origin)[0].is_number() || !(*origin)[1].is_number() ||
      !(*origin)[2].is_number()) {
    ThrowError(path, "has no \"grid_origin\" [x, y, z]: written by an older ibrdf; run `ibrdf uniformity` again");
  }
  for (int a = 0; a < 3; ++a) cells.origin[a] = (*origin)[a].get<double>();
  if (!uniformity.contains("materials") || !uniformity["materials"].contains("count") ||
      !uniformity["materials"]["count"].is_number_integer()) {
    ThrowError(path, "has no \"materials\".\"count\"");
  }
  cells.groups = uniformity["materials"]["count"].get<int>();
  cells.blend_of.assign(std::max(cells.groups, 0), {-1, -1});
  const nlohmann::json clusters = uniformity["materials"].value("clusters", nlohmann::json::array());
  const nlohmann::json object = uniformity.value("object_off_peak_brdf", nlohmann::json());
  const auto finite_triple = [](const nlohmann::json& v) {
    return v.is_array() && v.size() == 3 && v[0].is_number() && v[1].is_number() && v[2].is_number();
  };
  if (cells.groups > 1 && (!finite_triple(object) || clusters.size() != size_t(cells.groups) ||
                           !uniformity.contains("cluster_min_theta_h_deg"))) {
    ThrowError(path,
               "has no \"object_off_peak_brdf\", \"cluster_min_theta_h_deg\" or a centre per group: written "
               "by an older ibrdf; run `ibrdf uniformity` again");
  }
  if (uniformity.contains("cluster_min_theta_h_deg") && uniformity["cluster_min_theta_h_deg"].is_number()) {
    cells.max_cos_h = std::cos(uniformity["cluster_min_theta_h_deg"].get<double>() * kDegree);
  }
  for (size_t g = 0; g < clusters.size() && g < cells.blend_of.size(); ++g) {
    const nlohmann::json centre = clusters[g].value("ratio", nlohmann::json());
    if (finite_triple(object) && finite_triple(centre)) {
      Eigen::Vector3d c;
      for (int k = 0; k < 3; ++k) c[k] = std::log(centre[k].get<double>() * object[k].get<double>());
      cells.log_centre.push_back(c);
    }
    const nlohmann::json& pair = clusters[g].contains("blend_of") ? clusters[g]["blend_of"] : nlohmann::json();
    if (pair.is_array() && pair.size() == 2 && pair[0].is_number_integer() && pair[1].is_number_integer()) {
      cells.blend_of[g] = {pair[0].get<int>(), pair[1].get<int>()};
    }
  }
  if (!uniformity.contains("cell_list") || !uniformity["cell_list"].is_array()) {
    ThrowError(path, "has no \"cell_list\" (written without its cells)");
  }
  for (const nlohmann::json& cell : uniformity["cell_list"]) {
    if (!cell.contains("key") || !cell["key"].is_number_unsigned() || !cell.contains("material") ||
        !cell["material"].is_number_integer()) {
      ThrowError(path, "a cell of \"cell_list\" has no \"key\" or \"material\": run `ibrdf uniformity` again");
    }
    const int group = cell["material"].get<int>();
    if (group >= cells.groups) ThrowError(path, "a cell's material " + std::to_string(group) + " is not a group");
    if (group >= 0) cells.group_of_key.emplace(cell["key"].get<uint64_t>(), group);
  }
  return cells;
}

// Where one sample lies: its group (-1 none, -2 not located), and with a map its true material at
// the point (-1 within the margin of a boundary).
constexpr int kNotLocated = -2, kMixedSample = -3;
struct Placed {
  int group = kNotLocated;  // or -1: no group, kMixedSample: on a boundary or a blend
  int truth = -1;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  uint64_t key = 0;
};

// Pass 1 of the split: the off-peak samples' points and nearest groups.
struct OffPeakSample {
  Eigen::Vector3f point;
  int group = kOnPeak;
};

// A group as a basis of the projection: its table where measured, else its chosen fit (each group
// saw the surface from its own directions, so its table lacks data where another's has it); no value
// (negative) where neither has one. The evaluations the fit served are counted.
class TableOrFit : public BrdfModel {
 public:
  TableOrFit(const std::filesystem::path& folder, const std::string& chosen_model)
      : table_((folder / "brdf.binary").string()) {
    const std::filesystem::path fit = folder / (chosen_model + ".json");
    if (chosen_model != "none" && !chosen_model.empty() && std::filesystem::exists(fit)) fit_ = LoadMaterial(fit.string());
  }
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override {
    if (!(wi.z() > 0.0 && wo.z() > 0.0)) return Eigen::Vector3d::Zero();
    Eigen::Vector3d f = table_.Lookup(wi.normalized(), wo.normalized());
    if ((f.array() >= 0.0).all() || !fit_) return f;
    fitted_.fetch_add(1, std::memory_order_relaxed);
    const Eigen::Vector3d model = fit_->Eval(wi, wo);
    for (int k = 0; k < 3; ++k) {
      if (f[k] < 0.0) f[k] = model[k];
    }
    return f;
  }
  nlohmann::json ToJson() const override { return table_.ToJson(); }
  std::string ModelName() const override { return "merl"; }
  uint64_t fitted() const { return fitted_.load(); }

 private:
  MerlBrdf table_;
  std::unique_ptr<BrdfModel> fit_;
  mutable std::atomic<uint64_t> fitted_{0};
};

// Every cell of `located` as a combination of the reconstructed groups (their tables and fits, read back
// from `out_dir`), and with a map truth the weights scored against the truth's.
void ProjectCells(const std::string& out_dir, const MaterialMap* truth_map, const MaterialGroupsOptions& options,
                  std::vector<LocatedSample>* located, MaterialGroupsResult* result,
                  std::vector<std::unique_ptr<TableOrFit>>* tables_out, std::vector<const BrdfModel*>* bases_out) {
  std::vector<std::unique_ptr<TableOrFit>>& tables = *tables_out;
  std::vector<const BrdfModel*>& bases = *bases_out;
  for (size_t g = 0; g < result->groups.size(); ++g) {
    const MaterialGroup& group = result->groups[g];
    if (!group.reconstructed) continue;
    tables.push_back(std::make_unique<TableOrFit>(std::filesystem::path(out_dir) / group.folder,
                                                  group.reconstruction.chosen_model));
    bases.push_back(tables.back().get());
    result->bases.push_back(int(g));
  }
  if (bases.empty()) return;
  result->weights = ProjectOntoBases(located, bases, options.weights);
  uint64_t fitted = 0;
  for (const auto& table : tables) fitted += table->fitted();
  result->basis_evaluations = uint64_t(located->size()) * bases.size();
  result->basis_fit_evaluations = fitted;
  Log(1, "materials: " + result->weights.BriefReport(options.weights));
  if (!truth_map) return;
  // ProjectOntoBases left the samples sorted by cell, in the order of its cells.
  const size_t n_truth = truth_map->NumMaterials();
  std::vector<double> errors, mixed_errors;
  size_t at = 0;
  for (const CellWeights& cell : result->weights.cells) {
    Eigen::VectorXd truth = Eigen::VectorXd::Zero(Eigen::Index(n_truth));
    for (uint32_t i = 0; i < cell.samples; ++i, ++at) truth += truth_map->Weights((*located)[at].point.cast<double>());
    if (!cell.fitted || !(cell.weights.sum() > 0.0)) continue;
    truth /= double(cell.samples);
    Eigen::VectorXd measured = Eigen::VectorXd::Zero(Eigen::Index(n_truth));
    bool mapped = true;
    for (size_t b = 0; b < bases.size(); ++b) {
      const int material = result->groups[size_t(result->bases[b])].truth_material;
      if (material < 0) mapped = false;
      else measured[material] += cell.weights[Eigen::Index(b)] / cell.weights.sum();
    }
    if (!mapped) continue;
    const double error = 0.5 * (measured - truth).cwiseAbs().sum();
    errors.push_back(error);
    if (truth.maxCoeff() < 0.95) mixed_errors.push_back(error);
  }
  result->weights_scored_cells = errors.size();
  result->weights_mixed_cells = mixed_errors.size();
  if (!errors.empty()) {
    result->weights_error_median = Median(errors);
    result->weights_error_p95 = Percentile(errors, 0.95);
  }
  if (!mixed_errors.empty()) result->weights_mixed_error_median = Median(mixed_errors);
}

}  // namespace

bool MaterialGroupsOptions::Check(std::string* why) const {
  if (!reconstruct.Check(why)) return false;
  if (!(boundary_margin_m >= 0.0)) {
    *why = "the boundary margin must be at least 0";
    return false;
  }
  if (chunk_rows == 0) {
    *why = "chunk rows must be positive";
    return false;
  }
  if (!(purity > 0.0)) {
    *why = "the purity must be positive";
    return false;
  }
  if (neighbours < 1 || neighbours > 64) {
    *why = "neighbours must be 1 to 64";
    return false;
  }
  if (hold_out && photo < 0) {
    *why = "a held-out photo must be named (--photo N)";
    return false;
  }
  if (!weights.Check(why) || !pbrt.Check(why)) return false;
  return true;
}

MaterialGroupsResult MeasureMaterialGroups(const Session& session, const std::string& samples_path,
                                           const nlohmann::json& uniformity, const std::string& uniformity_path,
                                           const MaterialMap* truth_map, const std::string& truth_file,
                                           const MaterialGroupsOptions& options, const std::string& out_dir) {
  std::string why;
  if (!options.Check(&why)) ThrowError("material groups options", why);
  if (truth_map && !truth_file.empty()) ThrowError(truth_file, "a map truth and a material truth together");
  if (options.photo >= 0 && size_t(options.photo) >= session.photos.size()) {
    ThrowError(session.manifest_path, "photo " + std::to_string(options.photo) + " to predict: the session has " +
                                          std::to_string(session.photos.size()) + " photos (0 to " +
                                          std::to_string(int(session.photos.size()) - 1) + ")");
  }
  const auto start = std::chrono::steady_clock::now();
  const GroupedCells cells = ReadGroupedCells(uniformity, uniformity_path);
  const SurfaceLocator locator(session);
  MaterialGroupsResult result;
  result.truth_kind = truth_map ? "map" : truth_file.empty() ? "" : "material";
  const size_t n_truth = truth_map ? truth_map->NumMaterials() : 0;
  for (size_t k = 0; k < n_truth; ++k) result.truth_materials.push_back(truth_map->Name(k));
  result.confusion.assign(std::max(cells.groups, 0), std::vector<uint64_t>(n_truth, 0));
  // With groups: every located sample, its cell and group (each group's reconstruction takes its own,
  // and every cell is projected onto the reconstructed groups).
  std::vector<LocatedSample> located, held;
  std::vector<uint64_t> group_samples(std::max(cells.groups, 0), 0);

  // One group: the object's own reconstruction is the group's; the samples are only counted.
  const bool split = cells.groups > 1;
  // Pass 1 (with groups): each off-peak sample's point and the group its own value is nearest. The
  // cells' groups are the cells' majority; a cell on a sharp boundary holds two materials, so each
  // sample takes the group most of its nearest off-peak samples (of any photo) carry instead.
  OffPeakCloud cloud;
  std::vector<OffPeakSample> off_peak;
  const double log_purity = std::log1p(options.purity);
  if (split) {
    ForEachSampleChunk(samples_path, options.chunk_rows, [&](const BrdfSample* rows, size_t count, uint64_t) {
      off_peak.assign(count, OffPeakSample{});
      tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i < range.end(); ++i) {
          if (options.hold_out && rows[i].image == uint32_t(options.photo)) continue;
          const int group = OffPeakGroup(rows[i], cells, log_purity);
          if (group == kOnPeak) continue;
          Eigen::Vector3d point;
          if (locator.Locate(rows[i], &point) != SurfaceLocator::Outcome::kFound) continue;
          off_peak[i] = OffPeakSample{point.cast<float>(), group};
        }
      });
      for (const OffPeakSample& o : off_peak) {
        if (o.group == kOnPeak) continue;
        cloud.points.push_back(o.point);
        cloud.group.push_back(int8_t(o.group));
      }
    });
    result.off_peak_samples = cloud.points.size();
  }
  OffPeakTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  if (!cloud.points.empty()) tree.buildIndex();
  const int k_nearest = std::min<int>(options.neighbours, int(cloud.points.size()));
  const float max_distance_sq = float(cells.cell_m * cells.cell_m);

  std::vector<Placed> placed;
  result.samples =
      ForEachSampleChunk(samples_path, options.chunk_rows, [&](const BrdfSample* rows, size_t count, uint64_t) {
        placed.assign(count, Placed{});
        tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& range) {
          std::vector<uint32_t> index(std::max(k_nearest, 1));
          std::vector<float> distance_sq(std::max(k_nearest, 1));
          std::vector<int> votes(std::max(cells.groups, 1) + 1);  // the last: mixed
          for (size_t i = range.begin(); i < range.end(); ++i) {
            Eigen::Vector3d point;
            if (locator.Locate(rows[i], &point) != SurfaceLocator::Outcome::kFound) continue;
            placed[i].point = point.cast<float>();
            placed[i].key = UniformityCellKey(point, cells.origin, cells.cell_m);
            const auto it = cells.group_of_key.find(placed[i].key);
            placed[i].group = it == cells.group_of_key.end() ? -1 : it->second;
            if (k_nearest > 0) {
              const Eigen::Vector3f query = point.cast<float>();
              const size_t found = tree.knnSearch(query.data(), size_t(k_nearest), index.data(), distance_sq.data());
              std::fill(votes.begin(), votes.end(), 0);
              int near = 0;
              for (size_t j = 0; j < found; ++j) {
                if (distance_sq[j] > max_distance_sq) continue;
                const int group = cloud.group[index[j]];
                ++votes[group == kMixed ? cells.groups : group];
                ++near;
              }
              // Within a cell's edge of the point: the neighbours' majority, unless most of them are mixes or
              // another group has a vote (a boundary or a blend: the sample belongs to no one basis); with
              // no neighbours so near, the cell's group.
              if (near > 0) {
                const int most = int(std::max_element(votes.begin(), votes.end() - 1) - votes.begin());
                const int mixed = votes.back(), others = near - mixed - votes[most];
                placed[i].group = 2 * mixed >= near || others > 0 ? kMixedSample : most;
              }
            }
            if (truth_map && truth_map->BoundaryDistance(point) >= options.boundary_margin_m) {
              placed[i].truth = truth_map->Label(point);
            }
          }
        });
        for (size_t i = 0; i < count; ++i) {
          const Placed& p = placed[i];
          if (p.group == kNotLocated) {
            ++result.not_located;
            continue;
          }
          if (options.hold_out && rows[i].image == uint32_t(options.photo)) {
            // Held out: predicted from the model the other photos make, counted in no group.
            held.push_back(LocatedSample{rows[i], p.point, -1, p.key});
            ++result.held_out;
            continue;
          }
          if (split) located.push_back(LocatedSample{rows[i], p.point, int8_t(p.group), p.key});
          if (p.group == kMixedSample) {
            ++result.mixed;
            if (p.truth >= 0) ++result.mixed_scored;
            continue;
          }
          if (p.group < 0) {
            ++result.ungrouped;
            continue;
          }
          ++group_samples[p.group];
          if (p.truth >= 0) ++result.confusion[p.group][p.truth];
        }
      });

  result.groups.resize(group_samples.size());
  for (size_t g = 0; g < group_samples.size(); ++g) {
    MaterialGroup& group = result.groups[g];
    group.samples = split ? group_samples[g] : result.samples - result.not_located - result.ungrouped;
    group.blend_of = cells.blend_of[g];
    if (n_truth > 0) {
      const std::vector<uint64_t>& row = result.confusion[g];
      const auto most = std::max_element(row.begin(), row.end());
      if (*most > 0) {
        group.truth_material = int(most - row.begin());
        group.truth_name = truth_map->Name(group.truth_material);
        // A blend's samples away from the truth's boundaries are one material each, not a blend.
        if (group.blend_of[0] < 0) result.labels_right += double(*most);
      }
      for (uint64_t n : row) result.scored += n;
    }
  }
  // A sample away from the truth's boundaries that was called a mix is one material: not right.
  result.scored += result.mixed_scored;
  if (result.scored > 0) result.labels_right /= double(result.scored);

  std::vector<std::string> not_measured;  // the material groups too small to reconstruct
  for (size_t g = 0; split && g < group_samples.size(); ++g) {
    MaterialGroup& group = result.groups[g];
    if (group.blend_of[0] >= 0) {
      Log(1, "materials: group " + std::to_string(g) + " not reconstructed: a blend of groups " +
                 std::to_string(group.blend_of[0]) + " and " + std::to_string(group.blend_of[1]) + " (" +
                 std::to_string(group.samples) + " samples)");
      continue;
    }
    if (group.samples < options.min_group_samples) {
      Log(1, "materials: group " + std::to_string(g) + " not reconstructed: " + std::to_string(group.samples) +
                 " samples, under " + std::to_string(options.min_group_samples));
      not_measured.push_back("group " + std::to_string(g) + ": " + std::to_string(group.samples) + " samples");
      continue;
    }
    ReconstructOptions reconstruct = options.reconstruct;
    reconstruct.overwrite = false;
    reconstruct.name = (options.reconstruct.name.empty() ? std::string("material") : options.reconstruct.name) +
                       "-group-" + std::to_string(g);
    const std::filesystem::path folder = std::filesystem::path(out_dir) / ("group-" + std::to_string(g));
    if (group.truth_material >= 0) {
      // The group is scored against the material most of its samples carry, written beside it.
      const std::filesystem::path truth =
          std::filesystem::path(out_dir) / ("group-" + std::to_string(g) + "-truth.json");
      WriteJsonFile(truth.string(), truth_map->Material(group.truth_material).ToJson());
      reconstruct.truth_file = truth.string();
    } else {
      reconstruct.truth_file = truth_file;
    }
    Log(1, "materials: group " + std::to_string(g) + ": " + std::to_string(group.samples) + " samples" +
               (group.truth_name.empty() ? "" : " (mostly " + group.truth_name + ")"));
    std::vector<BrdfSample> own;
    own.reserve(group.samples);
    for (const LocatedSample& s : located) {
      if (s.group == int(g)) own.push_back(s.sample);
    }
    group.reconstruction = Reconstruct(own, reconstruct, folder.string(), samples_path);
    if (group.truth_material >= 0) {
      // The truth beside the group is named as the output folder will hold it (out_dir may be a
      // temporary name until committed).
      const std::string summary = (folder / "summary.json").string();
      nlohmann::json written = ReadJsonFile(summary);
      ReplaceString(&written, reconstruct.truth_file,
                    "../" + std::filesystem::path(reconstruct.truth_file).filename().string());
      WriteJsonFile(summary, written);
    }
    group.reconstructed = true;
    group.folder = folder.filename().string();
    group.material_name = reconstruct.name;
  }
  if (split) {
    std::vector<std::unique_ptr<TableOrFit>> tables;
    std::vector<const BrdfModel*> bases;
    ProjectCells(out_dir, truth_map, options, &located, &result, &tables, &bases);
    // The photo to predict: the one given, else the one with the most located samples.
    size_t photo = options.photo >= 0 ? size_t(options.photo) : 0;
    if (options.photo < 0) {
      std::vector<uint64_t> per_photo(session.photos.size(), 0);
      for (const LocatedSample& s : located) {
        if (s.sample.image < per_photo.size()) ++per_photo[s.sample.image];
      }
      photo = size_t(std::max_element(per_photo.begin(), per_photo.end()) - per_photo.begin());
    }
    if (!result.bases.empty()) {
      std::unique_ptr<BrdfModel> single;
      const std::string single_path = uniformity.value("brdf", "");
      if (!single_path.empty() && std::filesystem::exists(single_path)) single = std::make_unique<MerlBrdf>(single_path);
      result.prediction = PredictPhoto(session, photo, options.hold_out, options.hold_out ? held : located,
                                       result.weights, bases, cells.origin, cells.cell_m, single.get(), truth_map,
                                       out_dir);
      Log(1, "materials: " + result.prediction.BriefReport());
      VertexMaterials vertices;
      result.mesh = WriteMaterialMesh(session, result.weights, result.bases, cells.origin, cells.cell_m,
                                      (std::filesystem::path(out_dir) / "materials.ply").string(), &vertices);
      Log(1, "materials: " + result.mesh.BriefReport());
      if (result.mesh.written) {
        // The photo predicted below, rendered from the measured groups' pbrt-v4 materials.
        std::vector<std::string> snippets, names;
        for (int g : result.bases) {
          const MaterialGroup& group = result.groups[size_t(g)];
          snippets.push_back(group.folder + "/" + group.material_name + ".pbrt");
          names.push_back(group.material_name);
        }
        const bool exported = std::all_of(snippets.begin(), snippets.end(), [&](const std::string& snippet) {
          return std::filesystem::exists(std::filesystem::path(out_dir) / snippet);
        });
        if (exported) {
          result.pbrt = WritePbrtScene(session, photo, vertices, snippets, names, out_dir, options.pbrt);
          // ibrdf's render of the same model from the GGX fits the snippets were made from.
          std::vector<std::unique_ptr<BrdfModel>> ggx;
          std::vector<const BrdfModel*> fits;
          for (int g : result.bases) {
            const MaterialGroup& group = result.groups[size_t(g)];
            const std::filesystem::path fit = std::filesystem::path(out_dir) / group.folder / "ggx.json";
            if (!std::filesystem::exists(fit)) break;
            ggx.push_back(LoadMaterial(fit.string()));
            fits.push_back(ggx.back().get());
          }
          SceneModelRender render;
          if (fits.size() == result.bases.size()) {
            render = RenderSceneModel(session, photo, options.hold_out ? held : located, result.weights, fits,
                                      cells.origin, cells.cell_m, result.pbrt.light_scale, out_dir);
          }
          if (render.written) {
            result.pbrt.model_image = std::filesystem::path(render.image).filename().string();
            result.pbrt.model_pixels = render.pixels;
            result.pbrt.weight_sum_p05 = render.weight_sum_p05;
            result.pbrt.weight_sum_median = render.weight_sum_median;
            result.pbrt.weight_sum_p95 = render.weight_sum_p95;
            result.pbrt.full_model_ratio = render.full_model_ratio;
          }
        } else {
          result.pbrt.not_written = "a group has no pbrt-v4 material (its fits were not run: --no-fits)";
        }
        Log(1, "materials: " + result.pbrt.BriefReport());
      }
    }
    const std::string size_bound = "every group that is a material has at least " +
                                   std::to_string(options.min_group_samples) + " samples (--min-group-samples)";
    std::string measured;
    for (const std::string& item : not_measured) measured += (measured.empty() ? "" : "; ") + item;
    result.verdicts.push_back(MakeVerdict(
        "materials.measured", double(not_measured.size()),
        not_measured.empty() ? "every material group reconstructed"
                             : std::to_string(not_measured.size()) + " material group(s) too small to reconstruct (" +
                                   measured + ")",
        size_bound, not_measured.empty() ? VerdictLevel::kOk : VerdictLevel::kFail,
        "a material was found but not measured: photograph its region from more directions, or lower "
        "--min-group-samples; accepted, its cells are expressed by the other groups (materials.json's weights)"));
    const MaterialWeightsOptions& w = options.weights;
    if (result.weights.cells_fitted < 8) {
      result.verdicts.push_back(MakeVerdict(
          "materials.cells", double(result.weights.cells_fitted),
          std::to_string(result.weights.cells_fitted) + " cells with at least " + std::to_string(w.min_cell_samples) +
              " samples usable against every reconstructed group",
          "at least 8 fitted cells to judge the groups", VerdictLevel::kWarn,
          "the groups' combinations not judged: too few samples per cell (more photos, or a larger cell in "
          "`ibrdf uniformity --cell-mm`)"));
    } else {
      result.verdicts.push_back(MakeVerdict(
          "materials.cells", result.weights.not_fitting_fraction, result.weights.BriefReport(w),
          "under " + Fixed(100.0 * w.warn_fraction, 0) + " % of fitted cells (warn), " +
              Fixed(100.0 * w.fail_fraction, 0) + " % (fail)",
          VerdictAbove(result.weights.not_fitting_fraction, w.warn_fraction, w.fail_fraction),
          "the cells that fit no combination of the measured groups hold a material no group measured (a group "
          "too small to reconstruct, or two materials within the clustering's 1.6x of each other off the peak), "
          "or the geometry is wrong there (see align's verdicts); where: materials.json's weights.cell_list"));
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string MaterialGroupsResult::BriefReport() const {
  const uint64_t grouped = samples - not_located - ungrouped - mixed;
  std::string text = "materials: " + std::to_string(groups.size()) + (groups.size() == 1 ? " group" : " groups");
  if (groups.size() > 1) {
    text += " (";
    for (size_t g = 0; g < groups.size(); ++g) {
      text += (g ? " / " : "") + Fixed(grouped ? 100.0 * double(groups[g].samples) / double(grouped) : 0.0, 0);
    }
    text += " % of " + std::to_string(grouped) + " grouped samples)";
  } else {
    text += ": one material, measured as reconstruction/ (not reconstructed again)";
  }
  text += "; " + std::to_string(mixed) + " samples on a boundary or blend (no basis), " + std::to_string(ungrouped) +
          " in no group, " + std::to_string(not_located) + " not located";
  if (truth_kind == "map" && scored > 0) {
    text += "; labels right on " + Fixed(100.0 * labels_right, 1) + " % of " + std::to_string(scored) +
            " samples away from the truth's boundaries";
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    const MaterialGroup& group = groups[g];
    if (group.blend_of[0] >= 0) {
      text += "; group " + std::to_string(g) + " a blend of " + std::to_string(group.blend_of[0]) + " and " +
              std::to_string(group.blend_of[1]);
    }
    if (!group.reconstructed || !group.reconstruction.scored) continue;
    text += "; group " + std::to_string(g) + (group.truth_name.empty() ? "" : " (" + group.truth_name + ")") +
            " table rel. RMS " + Fixed(100.0 * group.reconstruction.error_against_truth.rel_rms_all, 1) + " %";
  }
  if (!bases.empty()) {
    text += "; " + std::to_string(weights.cells_not_fitting) + " of " + std::to_string(weights.cells_fitted) +
            " cells fit no combination of the groups";
    if (weights_scored_cells > 0) {
      text += "; weights off the truth's by " + Fixed(100.0 * weights_error_median, 1) + " % median (" +
              Fixed(100.0 * weights_mixed_error_median, 1) + " % in " + std::to_string(weights_mixed_cells) +
              " mixed cells)";
    }
  }
  if (prediction.done) text += "; " + prediction.BriefReport();
  return text + "; " + Fixed(seconds, 1) + " s";
}

nlohmann::json MaterialGroupsResult::ToJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (size_t g = 0; g < groups.size(); ++g) {
    const MaterialGroup& group = groups[g];
    nlohmann::json entry = {{"group", g}, {"samples", group.samples}, {"reconstructed", group.reconstructed}};
    if (group.blend_of[0] >= 0) entry["blend_of"] = {group.blend_of[0], group.blend_of[1]};
    if (group.reconstructed) {
      entry["folder"] = group.folder;
      entry["material_name"] = group.material_name;
      entry["summary"] = group.folder + "/summary.json";
      entry["chosen_model"] = group.reconstruction.chosen_model;
      if (group.reconstruction.scored) {
        entry["error_against_truth"] = ibrdf::ToJson(group.reconstruction.error_against_truth);
      }
    }
    if (group.truth_material >= 0) {
      entry["truth_material"] = group.truth_material;
      entry["truth_name"] = group.truth_name;
    }
    list.push_back(entry);
  }
  nlohmann::json value = {{"format", "ibrdf-materials"},
                          {"version", 1},
                          {"samples",
                           {{"rows", samples},
                            {"not_located", not_located},
                            {"off_peak", off_peak_samples},
                            {"mixed", mixed},
                            {"mixed_away_from_boundaries", mixed_scored},
                            {"ungrouped", ungrouped},
                            {"held_out", held_out}}},
                          {"groups", list},
                          {"truth", truth_kind.empty() ? nlohmann::json(nullptr) : nlohmann::json(truth_kind)},
                          {"timings_s", {{"total", seconds}}}};
  if (!bases.empty()) {
    nlohmann::json cell_list = nlohmann::json::array();
    const auto triple = [](const Eigen::Vector3d& v) {
      nlohmann::json out = nlohmann::json::array();
      for (int k = 0; k < 3; ++k) out.push_back(std::isfinite(v[k]) ? nlohmann::json(v[k]) : nlohmann::json(nullptr));
      return out;
    };
    for (const CellWeights& cell : weights.cells) {
      nlohmann::json entry = {{"key", cell.key},
                              {"centre", {cell.centre.x(), cell.centre.y(), cell.centre.z()}},
                              {"samples", cell.samples},
                              {"fitted", cell.fitted}};
      if (cell.fitted) {
        entry["weights"] = std::vector<double>(cell.weights.data(), cell.weights.data() + cell.weights.size());
        entry["ratio"] = triple(cell.ratio);
        entry["noise"] = triple(cell.noise);
        entry["rel_rms"] = cell.rel_rms;
        entry["fits"] = cell.fits;
        entry["dominant_group"] = bases[size_t(cell.dominant)];
      }
      cell_list.push_back(entry);
    }
    nlohmann::json w = {{"bases", bases},
                        {"cells", weights.cells.size()},
                        {"cells_fitted", weights.cells_fitted},
                        {"cells_not_fitting", weights.cells_not_fitting},
                        {"not_fitting_fraction", weights.not_fitting_fraction},
                        {"median_rel_rms", weights.median_rel_rms},
                        {"basis_evaluations", basis_evaluations},
                        {"basis_fit_evaluations", basis_fit_evaluations},
                        {"bases_are",
                         "each group's table where it has data, else its chosen fit (basis_fit_evaluations of "
                         "basis_evaluations)"},
                        {"seconds", weights.seconds},
                        {"cell_list", cell_list}};
    if (truth_kind == "map") {
      w["truth"] = {{"scored_cells", weights_scored_cells},
                    {"error_median", weights_error_median},
                    {"error_p95", weights_error_p95},
                    {"mixed_cells", weights_mixed_cells},
                    {"mixed_error_median", weights_mixed_error_median}};
    }
    value["weights"] = w;
    nlohmann::json mesh_json = {{"written", mesh.written}};
    if (mesh.written) {
      mesh_json.update({{"file", "materials.ply"},
                        {"vertices", mesh.vertices},
                        {"from_own_cell", mesh.own_cell},
                        {"from_near_cell", mesh.near_cell},
                        {"from_none", mesh.none},
                        {"in_cells_not_fitting", mesh.not_fitting}});
    } else {
      mesh_json["reason"] = mesh.not_written;
    }
    value["mesh"] = mesh_json;
    nlohmann::json pbrt_json = {{"written", pbrt.written}};
    if (pbrt.written) {
      pbrt_json.update(
          {{"scene", pbrt.file},
           {"image", pbrt.image},
           {"photo", pbrt.photo},
           {"materials", pbrt.materials},
           {"faces", pbrt.faces},
           {"faces_without_weights", pbrt.faces_unmeasured},
           {"undistorted", pbrt.undistorted},
           {"light_scale", pbrt.light_scale},
           {"faces_brighter_than_the_light_scale", pbrt.faces_scale_clipped},
           {"mitsuba_scene", pbrt.mitsuba_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(pbrt.mitsuba_file)},
           {"mitsuba_render", pbrt.mitsuba_file.empty()
                                  ? nlohmann::json(pbrt.mitsuba_not_written)
                                  : nlohmann::json("cd mitsuba && mitsuba " +
                                                   std::filesystem::path(pbrt.mitsuba_file).filename().string())},
           {"ibrdf_image", pbrt.model_image.empty() ? nlohmann::json(nullptr) : nlohmann::json(pbrt.model_image)},
           {"ibrdf_pixels", pbrt.model_pixels},
           {"weight_sums",
            {{"p05", pbrt.weight_sum_p05},
             {"median", pbrt.weight_sum_median},
             {"p95", pbrt.weight_sum_p95},
             {"full_weights_brightness_ratio", pbrt.full_model_ratio}}},
           {"render", "cd " + std::filesystem::path(pbrt.file).parent_path().string() + " && pbrt " +
                          std::filesystem::path(pbrt.file).filename().string() + " (writes " + pbrt.image +
                          " there)"}});
    } else {
      pbrt_json["reason"] = pbrt.not_written.empty() ? mesh_json.value("reason", "") : pbrt.not_written;
    }
    value["pbrt"] = pbrt_json;
    if (prediction.done) value["prediction"] = prediction.ToJson();
  }
  value["verdicts"] = VerdictsToJson(verdicts);
  if (truth_kind == "map") {
    value["labels"] = {{"truth_materials", truth_materials},
                       {"confusion_groups_by_materials", confusion},
                       {"scored_samples", scored},
                       {"right_fraction", labels_right}};
  }
  return value;
}

}  // namespace ibrdf

// A spatially varying material for synthetic sessions (Lensch et al. 2003's model of a surface): at
// each surface point a convex combination of a few basis materials, f(x; wi, wo) = sum_k w_k(x) f_k(wi,
// wo) with w_k >= 0 and sum_k w_k = 1. Synth renders every pixel with the weights at its hit point, and
// truth.json keeps the map (ToJson), so the per-point truth is recomputed from a derendered point's
// world position (FromJson, Weights) without any per-pixel file.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "core/brdf_model.h"
#include "core/kind.h"

namespace ibrdf {

// How the surface is divided into regions (one kind today; the switch statements in material_map.cc
// make every new kind handle each use).
enum class MaterialMapKind {
  // Regions are sectors of azimuth about an axis through a centre (a squash's or pot's stripes):
  // stripe s covers azimuths [s, s + 1) * 2 pi / stripes and holds material stripe_materials[s].
  // Azimuth counts counter-clockwise about the axis from world x (world y for an axis along x).
  kStripes,
  IBRDF_DUMMY_KIND
};

class MaterialMap {
 public:
  // The boundary between stripe s and s + 1 (cyclic) is sharp (blend_m[s] = 0) or a linear blend of
  // the two materials over blend_m[s] metres of arc, measured at the point's distance from the axis
  // (centred on the boundary; near the axis, where a stripe is narrower than its blends, the blends
  // overlap and the stripe's own weight may vanish). Throws Error naming `source` for no material, fewer
  // than 2 stripes, a stripe whose material index is out of range, a negative blend or a zero axis.
  MaterialMap(std::vector<std::string> names, std::vector<std::shared_ptr<const BrdfModel>> materials,
              const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, std::vector<int> stripe_materials,
              std::vector<double> blend_m, const std::string& source);

  // A map file (JSON): {"kind": "stripes", "centre": [x, y, z] (metres, world), "axis": [x, y, z],
  // "materials": ["a.json", ...] (paths relative to the file), "stripes": [0, 1, 2, ...] (each
  // stripe's material), "blend_mm": [0, 20, ...] (each stripe's boundary with the next) or one number
  // for all}. Throws Error naming the file and the field for anything missing or wrong.
  static MaterialMap Load(const std::string& path);
  // truth.json's "material_map" (ToJson's output: the materials embedded, not by path).
  static MaterialMap FromJson(const nlohmann::json& value, const std::string& source);
  nlohmann::json ToJson() const;

  MaterialMapKind kind() const { return kind_; }
  size_t NumMaterials() const { return materials_.size(); }
  const std::string& Name(size_t k) const { return names_[k]; }
  const BrdfModel& Material(size_t k) const { return *materials_[k]; }

  // The weights at a world point (NumMaterials() entries, non-negative, summing to 1).
  Eigen::VectorXd Weights(const Eigen::Vector3d& world_point) const;
  // The material with the largest weight at the point.
  int Label(const Eigen::Vector3d& world_point) const;
  // Metres from the point to the nearest point whose weights are mixed or whose label differs (a sharp
  // boundary, or the edge of a blend; 0 inside a blend), along the circle about the axis.
  double BoundaryDistance(const Eigen::Vector3d& world_point) const;
  // f at the point: the weights' combination of the materials' values.
  Eigen::Vector3d Eval(const Eigen::Vector3d& world_point, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const;

 private:
  // The point's stripe and its azimuth within it (radians from the stripe's start), and its radius.
  void Locate(const Eigen::Vector3d& world_point, int* stripe, double* within, double* radius) const;

  MaterialMapKind kind_ = MaterialMapKind::kStripes;
  std::vector<std::string> names_;
  std::vector<std::shared_ptr<const BrdfModel>> materials_;
  Eigen::Vector3d centre_, axis_, u_, v_;  // u_, v_: an orthonormal basis across the axis
  std::vector<int> stripe_materials_;
  std::vector<double> blend_m_;
};

}  // namespace ibrdf

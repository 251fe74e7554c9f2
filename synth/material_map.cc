#include "synth/material_map.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/math.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

const char* KindName(MaterialMapKind kind) {
  switch (kind) {
    case MaterialMapKind::kStripes:
      return "stripes";
  }
  return "";
}

MaterialMapKind KindFromName(const std::string& name, const std::string& source) {
  if (name == KindName(MaterialMapKind::kStripes)) return MaterialMapKind::kStripes;
  ThrowError(source, "material map kind \"" + name + "\" is not one of: stripes");
}

Eigen::Vector3d Vector3(const nlohmann::json& value, const std::string& source, const std::string& field) {
  if (!value.is_array() || value.size() != 3) ThrowError(source, "\"" + field + "\" must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!value[i].is_number()) ThrowError(source, "\"" + field + "\" must be an array of 3 numbers");
    v[i] = value[i].get<double>();
  }
  return v;
}

const nlohmann::json& Field(const nlohmann::json& value, const std::string& source, const std::string& field) {
  const auto it = value.find(field);
  if (it == value.end()) ThrowError(source, "material map has no \"" + field + "\"");
  return *it;
}

// The map from its JSON; `directory` resolves materials given by path ("" for truth.json's embedded ones).
MaterialMap ParseMap(const nlohmann::json& value, const std::string& source, const std::string& directory) {
  if (!value.is_object()) ThrowError(source, "a material map must be a JSON object");
  const MaterialMapKind kind = KindFromName(Field(value, source, "kind").get<std::string>(), source);
  std::vector<std::string> names;
  std::vector<std::shared_ptr<const BrdfModel>> materials;
  const nlohmann::json& list = Field(value, source, "materials");
  if (!list.is_array()) ThrowError(source, "\"materials\" must be an array");
  for (size_t k = 0; k < list.size(); ++k) {
    const nlohmann::json& entry = list[k];
    if (entry.is_string()) {
      if (directory.empty()) ThrowError(source, "materials must be embedded here, not given by path");
      const fs::path path = fs::path(directory) / entry.get<std::string>();
      // The material's own error (its file, its field) under the map's field that named it.
      try {
        materials.push_back(LoadMaterial(path.string()));
      } catch (const Error& e) {
        ThrowError(source + ": /materials/" + std::to_string(k), e.what());
      }
      names.push_back(path.stem().string());
    } else if (entry.is_object() && entry.contains("material")) {
      materials.push_back(
          MaterialFromJson(entry["material"], source, "/materials/" + std::to_string(k) + "/material"));
      names.push_back(entry.value("name", "material " + std::to_string(k)));
    } else {
      ThrowError(source, "materials[" + std::to_string(k) + "] must be a path or {\"name\", \"material\"}");
    }
  }
  std::vector<int> stripes;
  std::vector<double> blend_m;
  switch (kind) {
    case MaterialMapKind::kStripes: {
      const nlohmann::json& s = Field(value, source, "stripes");
      if (!s.is_array()) ThrowError(source, "\"stripes\" must be an array of material indices");
      for (const nlohmann::json& index : s) {
        if (!index.is_number_integer()) ThrowError(source, "\"stripes\" must be an array of material indices");
        stripes.push_back(index.get<int>());
      }
      const nlohmann::json& blend = Field(value, source, "blend_mm");
      if (blend.is_number()) {
        blend_m.assign(stripes.size(), blend.get<double>() * 1e-3);
      } else if (blend.is_array() && blend.size() == stripes.size()) {
        for (const nlohmann::json& b : blend) {
          if (!b.is_number()) ThrowError(source, "\"blend_mm\" must hold numbers");
          blend_m.push_back(b.get<double>() * 1e-3);
        }
      } else {
        ThrowError(source, "\"blend_mm\" must be a number or one number per stripe");
      }
      break;
    }
  }
  return MaterialMap(std::move(names), std::move(materials), Vector3(Field(value, source, "centre"), source, "centre"),
                     Vector3(Field(value, source, "axis"), source, "axis"), std::move(stripes), std::move(blend_m),
                     source);
}

}  // namespace

MaterialMap::MaterialMap(std::vector<std::string> names, std::vector<std::shared_ptr<const BrdfModel>> materials,
                         const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, std::vector<int> stripe_materials,
                         std::vector<double> blend_m, const std::string& source)
    : names_(std::move(names)),
      materials_(std::move(materials)),
      centre_(centre),
      stripe_materials_(std::move(stripe_materials)),
      blend_m_(std::move(blend_m)) {
  if (materials_.empty() || names_.size() != materials_.size()) ThrowError(source, "a material map needs materials");
  if (!(axis.norm() > 0.0) || !axis.allFinite()) ThrowError(source, "the material map's axis must be nonzero");
  if (stripe_materials_.size() < 2) ThrowError(source, "a stripe map needs at least 2 stripes");
  if (blend_m_.size() != stripe_materials_.size()) ThrowError(source, "one blend width per stripe boundary");
  for (int m : stripe_materials_) {
    if (m < 0 || size_t(m) >= materials_.size()) {
      ThrowError(source, "stripe material " + std::to_string(m) + " is not one of the " +
                             std::to_string(materials_.size()) + " materials");
    }
  }
  for (double b : blend_m_) {
    if (!(b >= 0.0)) ThrowError(source, "blend widths must be at least 0");
  }
  axis_ = axis.normalized();
  // Azimuth counts from world x projected across the axis (world y when the axis is along x), so a
  // map reads the same whatever axis it is given.
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();
  if (std::abs(axis_.dot(reference)) > 0.9) reference = Eigen::Vector3d::UnitY();
  u_ = (reference - axis_ * axis_.dot(reference)).normalized();
  v_ = axis_.cross(u_);
}

MaterialMap MaterialMap::Load(const std::string& path) {
  return ParseMap(ReadJsonFile(path), path, fs::path(path).parent_path().string().empty()
                                                ? std::string(".")
                                                : fs::path(path).parent_path().string());
}

MaterialMap MaterialMap::FromJson(const nlohmann::json& value, const std::string& source) {
  return ParseMap(value, source, "");
}

nlohmann::json MaterialMap::ToJson() const {
  nlohmann::json materials = nlohmann::json::array();
  for (size_t k = 0; k < materials_.size(); ++k) {
    materials.push_back({{"name", names_[k]}, {"material", materials_[k]->ToJson()}});
  }
  nlohmann::json blend_mm = nlohmann::json::array();
  for (double b : blend_m_) blend_mm.push_back(b * 1e3);
  nlohmann::json value = {{"kind", KindName(kind_)},
                          {"centre", {centre_.x(), centre_.y(), centre_.z()}},
                          {"axis", {axis_.x(), axis_.y(), axis_.z()}},
                          {"materials", materials}};
  switch (kind_) {
    case MaterialMapKind::kStripes:
      value["stripes"] = stripe_materials_;
      value["blend_mm"] = blend_mm;
      break;
  }
  return value;
}

void MaterialMap::Locate(const Eigen::Vector3d& world_point, int* stripe, double* within, double* radius) const {
  const Eigen::Vector3d d = world_point - centre_;
  const Eigen::Vector3d across = d - axis_ * axis_.dot(d);
  double phi = std::atan2(v_.dot(across), u_.dot(across));
  if (phi < 0.0) phi += 2.0 * kPi;
  const int n = int(stripe_materials_.size());
  const double width = 2.0 * kPi / n;
  *stripe = std::clamp(int(phi / width), 0, n - 1);
  *within = phi - *stripe * width;
  *radius = across.norm();
}

Eigen::VectorXd MaterialMap::Weights(const Eigen::Vector3d& world_point) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(Eigen::Index(materials_.size()));
  switch (kind_) {
    case MaterialMapKind::kStripes: {
      int s = 0;
      double within = 0.0, r = 0.0;
      Locate(world_point, &s, &within, &r);
      const int n = int(stripe_materials_.size());
      const double width = 2.0 * kPi / n;
      const int previous = (s + n - 1) % n, next = (s + 1) % n;
      // Each blend hands the neighbour up to half the weight at the boundary, falling linearly to 0 at
      // half the blend's width inside the stripe.
      auto share = [r](double arc_angle, double blend) {
        const double half = 0.5 * blend;
        const double d = arc_angle * r;
        return half > 0.0 && d < half ? 0.5 * (1.0 - d / half) : 0.0;
      };
      const double w_previous = share(within, blend_m_[previous]);
      const double w_next = share(width - within, blend_m_[s]);
      w[stripe_materials_[previous]] += w_previous;
      w[stripe_materials_[next]] += w_next;
      w[stripe_materials_[s]] += 1.0 - w_previous - w_next;
      break;
    }
  }
  return w;
}

int MaterialMap::Label(const Eigen::Vector3d& world_point) const {
  Eigen::Index k = 0;
  Weights(world_point).maxCoeff(&k);
  return int(k);
}

double MaterialMap::BoundaryDistance(const Eigen::Vector3d& world_point) const {
  switch (kind_) {
    case MaterialMapKind::kStripes: {
      int s = 0;
      double within = 0.0, r = 0.0;
      Locate(world_point, &s, &within, &r);
      const int n = int(stripe_materials_.size());
      const double width = 2.0 * kPi / n;
      const int own = stripe_materials_[s];
      // Walks the stripes away from the point on each side until one holds another material; its
      // boundary's blend reaches half its width towards the point.
      double best = std::numeric_limits<double>::infinity();
      for (int side = -1; side <= 1; side += 2) {
        double arc = side < 0 ? within * r : (width - within) * r;
        int current = s;
        for (int step = 0; step < n; ++step) {
          const int neighbour = (current + side + n) % n;
          const int boundary = side < 0 ? neighbour : current;  // blend_m_[i]: between stripe i and i + 1
          if (stripe_materials_[neighbour] != own) {
            best = std::min(best, std::max(0.0, arc - 0.5 * blend_m_[boundary]));
            break;
          }
          arc += width * r;
          current = neighbour;
        }
      }
      return best;
    }
  }
  return 0.0;
}

Eigen::Vector3d MaterialMap::Eval(const Eigen::Vector3d& world_point, const Eigen::Vector3d& wi,
                                  const Eigen::Vector3d& wo) const {
  const Eigen::VectorXd w = Weights(world_point);
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    if (w[k] > 0.0) f += w[k] * materials_[size_t(k)]->Eval(wi, wo);
  }
  return f;
}

}  // namespace ibrdf

#include "core/merl_brdf.h"

#include <filesystem>

#include <nlohmann/json.hpp>

namespace ibrdf {

MerlBrdf::MerlBrdf(const std::string& path) : MerlBrdf(ReadMerl(path), path) {}

MerlBrdf::MerlBrdf(MerlTable table, std::string path)
    : table_(std::move(table)), path_(std::filesystem::absolute(path).lexically_normal().string()) {
  for (size_t flat = 0; flat < kMerlCells; ++flat) cells_without_data_ += !table_.Measured(flat);
}

Eigen::Vector3d MerlBrdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (!(wi.z() > 0.0 && wo.z() > 0.0)) return Eigen::Vector3d::Zero();
  lookups_.fetch_add(1, std::memory_order_relaxed);
  const Eigen::Vector3d f = table_.Lookup(wi.normalized(), wo.normalized());
  if ((f.array() < 0.0).any()) {
    no_data_lookups_.fetch_add(1, std::memory_order_relaxed);
    return Eigen::Vector3d::Zero();
  }
  return f;
}

nlohmann::json MerlBrdf::ToJson() const { return {{"model", "merl"}, {"file", path_}}; }

bool IsMerlPath(const std::string& path) { return std::filesystem::path(path).extension() == ".binary"; }

}  // namespace ibrdf

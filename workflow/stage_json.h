// Typed reading of the JSON files other stages write (samples.npy.json, consistency.json, stamps ...).
// Values are addressed by JSON pointer ("/overall/median_rel_error"); a missing or wrongly typed
// required value is an Error naming the file and the pointer, an optional one falls back when absent
// (a present one of the wrong type is still an Error). Unlike the session's strict reader
// (core/json_reader.h), unknown keys are fine: a stage may write more than the reader uses.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ibrdf {

class StageJson {
 public:
  // `file` names the source in messages.
  StageJson(nlohmann::json value, std::string file);
  // Reads `path`: nullopt when it does not exist; an Error naming it when it is not JSON.
  static std::optional<StageJson> ReadIfExists(const std::string& path);

  const std::string& file() const { return file_; }
  const nlohmann::json& root() const { return value_; }
  // True when `pointer` names a value (null included).
  bool Has(const std::string& pointer) const;
  // "file: pointer", for messages.
  std::string Where(const std::string& pointer) const;

  // Required values: missing or wrongly typed is an Error naming the file and the pointer.
  const nlohmann::json& Value(const std::string& pointer) const;   // of any type
  const nlohmann::json& Object(const std::string& pointer) const;  // a JSON object
  // A figure: a number, null (a NaN as nlohmann writes it), or an array of them (per channel).
  const nlohmann::json& Figure(const std::string& pointer) const;
  std::string String(const std::string& pointer) const;
  double Number(const std::string& pointer) const;
  int64_t Integer(const std::string& pointer) const;
  uint64_t Count(const std::string& pointer) const;  // a non-negative integer
  bool Boolean(const std::string& pointer) const;
  std::vector<std::string> Strings(const std::string& pointer) const;

  // Optional values: `fallback` when absent.
  nlohmann::json ValueOr(const std::string& pointer, const nlohmann::json& fallback) const;
  nlohmann::json ObjectOr(const std::string& pointer, const nlohmann::json& fallback) const;
  nlohmann::json FigureOr(const std::string& pointer, const nlohmann::json& fallback) const;
  std::string String(const std::string& pointer, const std::string& fallback) const;
  double Number(const std::string& pointer, double fallback) const;
  uint64_t Count(const std::string& pointer, uint64_t fallback) const;
  bool Boolean(const std::string& pointer, bool fallback) const;

 private:
  const nlohmann::json* Find(const std::string& pointer) const;
  [[noreturn]] void TypeError(const std::string& pointer, const std::string& expected) const;

  nlohmann::json value_;
  std::string file_;
};

}  // namespace ibrdf

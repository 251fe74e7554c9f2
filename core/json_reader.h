// Strict reading of JSON configuration (session manifests, materials, truth files).
//
// Every value is read through a JsonObject that knows its file and its JSON-pointer path, so errors read
// "session.json: /light/intensity: expected an array of 3 numbers, got a string". Keys that were never
// read are errors when Finish() is called (Mitsuba's rule: an unused parameter is a mistake).
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace ibrdf {

// Parses a JSON file; throws Error naming the file and the line on a syntax error.
nlohmann::json ReadJsonFile(const std::string& path);

// Writes JSON to `path` atomically (temporary file, then rename), pretty-printed.
void WriteJsonFile(const std::string& path, const nlohmann::json& value);

class JsonObject {
 public:
  // `file` names the source in messages; `pointer` is this object's JSON pointer ("" for the root).
  JsonObject(const nlohmann::json& value, std::string file, std::string pointer = "");

  bool Has(const std::string& key) const;
  // "file: /pointer/key" for messages about a field.
  std::string Where(const std::string& key = "") const;

  // Required fields: missing or wrongly typed is an Error naming the field.
  double Number(const std::string& key);
  int Integer(const std::string& key);
  bool Boolean(const std::string& key);
  std::string String(const std::string& key);
  Eigen::Vector3d Vector3(const std::string& key);
  std::vector<double> Numbers(const std::string& key);
  JsonObject Object(const std::string& key);
  // An array of objects.
  std::vector<JsonObject> Objects(const std::string& key);
  // The raw value (for free-form blocks such as a material kept verbatim).
  const nlohmann::json& Raw(const std::string& key);

  // Optional fields: the default when absent; wrongly typed is still an Error.
  double Number(const std::string& key, double fallback);
  int Integer(const std::string& key, int fallback);
  bool Boolean(const std::string& key, bool fallback);
  std::string String(const std::string& key, const std::string& fallback);

  // Errors on any key that was never read, listing the keys this object accepts.
  void Finish() const;

  const nlohmann::json& value() const { return *value_; }
  const std::string& file() const { return file_; }

 private:
  const nlohmann::json& Field(const std::string& key);
  [[noreturn]] void TypeError(const std::string& key, const std::string& expected) const;

  const nlohmann::json* value_;
  std::string file_;
  std::string pointer_;
  std::set<std::string> read_;
};

// "a string", "a number" ... for messages.
std::string JsonTypeName(const nlohmann::json& value);

nlohmann::json ToJson(const Eigen::Vector3d& v);

}  // namespace ibrdf

#include "workflow/stage_json.h"

#include <cstdint>
#include <filesystem>

#include "core/error.h"
#include "core/json_reader.h"

namespace ibrdf {
namespace {

bool IsFigureValue(const nlohmann::json& value) { return value.is_number() || value.is_null(); }

bool IsFigure(const nlohmann::json& value) {
  if (IsFigureValue(value)) return true;
  if (!value.is_array()) return false;
  for (const nlohmann::json& element : value) {
    if (!IsFigureValue(element)) return false;
  }
  return true;
}

}  // namespace

StageJson::StageJson(nlohmann::json value, std::string file) : value_(std::move(value)), file_(std::move(file)) {}

std::optional<StageJson> StageJson::ReadIfExists(const std::string& path) {
  if (!std::filesystem::exists(path)) return std::nullopt;
  return StageJson(ReadJsonFile(path), path);
}

// Walks "/a/b/0": object keys and array indices; nullptr when any step is absent.
const nlohmann::json* StageJson::Find(const std::string& pointer) const {
  IBRDF_CHECK(pointer.empty() || pointer[0] == '/') << "not a JSON pointer: " << pointer;
  const nlohmann::json* node = &value_;
  size_t start = 1;
  while (start <= pointer.size() && !pointer.empty()) {
    const size_t end = std::min(pointer.find('/', start), pointer.size());
    const std::string token = pointer.substr(start, end - start);
    if (node->is_object()) {
      const auto it = node->find(token);
      if (it == node->end()) return nullptr;
      node = &*it;
    } else if (node->is_array()) {
      if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos) return nullptr;
      const size_t index = std::stoul(token);
      if (index >= node->size()) return nullptr;
      node = &(*node)[index];
    } else {
      return nullptr;
    }
    start = end + 1;
  }
  return node;
}

bool StageJson::Has(const std::string& pointer) const { return Find(pointer) != nullptr; }

std::string StageJson::Where(const std::string& pointer) const { return file_ + ": " + pointer; }

void StageJson::TypeError(const std::string& pointer, const std::string& expected) const {
  ThrowError(Where(pointer), "expected " + expected + ", got " + JsonTypeName(*Find(pointer)));
}

const nlohmann::json& StageJson::Value(const std::string& pointer) const {
  const nlohmann::json* value = Find(pointer);
  if (!value) ThrowError(Where(pointer), "missing");
  return *value;
}

const nlohmann::json& StageJson::Object(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_object()) TypeError(pointer, "an object");
  return value;
}

const nlohmann::json& StageJson::Figure(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!IsFigure(value)) TypeError(pointer, "a number or an array of numbers");
  return value;
}

std::string StageJson::String(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_string()) TypeError(pointer, "a string");
  return value.get<std::string>();
}

double StageJson::Number(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_number()) TypeError(pointer, "a number");
  return value.get<double>();
}

int64_t StageJson::Integer(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_number_integer() || (value.is_number_unsigned() && value.get<uint64_t>() > uint64_t(INT64_MAX))) {
    TypeError(pointer, "an integer");
  }
  return value.get<int64_t>();
}

uint64_t StageJson::Count(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_number_unsigned() && !(value.is_number_integer() && value.get<int64_t>() >= 0)) {
    TypeError(pointer, "a non-negative integer");
  }
  return value.get<uint64_t>();
}

bool StageJson::Boolean(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_boolean()) TypeError(pointer, "true or false");
  return value.get<bool>();
}

std::vector<std::string> StageJson::Strings(const std::string& pointer) const {
  const nlohmann::json& value = Value(pointer);
  if (!value.is_array()) TypeError(pointer, "an array of strings");
  std::vector<std::string> strings;
  for (const nlohmann::json& element : value) {
    if (!element.is_string()) TypeError(pointer, "an array of strings");
    strings.push_back(element.get<std::string>());
  }
  return strings;
}

nlohmann::json StageJson::ValueOr(const std::string& pointer, const nlohmann::json& fallback) const {
  return Has(pointer) ? Value(pointer) : fallback;
}

nlohmann::json StageJson::ObjectOr(const std::string& pointer, const nlohmann::json& fallback) const {
  return Has(pointer) ? Object(pointer) : fallback;
}

nlohmann::json StageJson::FigureOr(const std::string& pointer, const nlohmann::json& fallback) const {
  return Has(pointer) ? Figure(pointer) : fallback;
}

std::string StageJson::String(const std::string& pointer, const std::string& fallback) const {
  return Has(pointer) ? String(pointer) : fallback;
}

double StageJson::Number(const std::string& pointer, double fallback) const {
  return Has(pointer) ? Number(pointer) : fallback;
}

uint64_t StageJson::Count(const std::string& pointer, uint64_t fallback) const {
  return Has(pointer) ? Count(pointer) : fallback;
}

bool StageJson::Boolean(const std::string& pointer, bool fallback) const {
  return Has(pointer) ? Boolean(pointer) : fallback;
}

}  // namespace ibrdf

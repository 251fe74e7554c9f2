#include "core/json_reader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {

nlohmann::json ReadJsonFile(const std::string& path) {
  // A regular file of bounded size only: a FIFO or /dev/zero would otherwise hang or fill memory.
  RequireFile(path, "JSON file");
  constexpr uintmax_t kMaxJsonBytes = uintmax_t(256) << 20;
  std::error_code error;
  const uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error || bytes > kMaxJsonBytes) {
    ThrowError(path, error ? "cannot read the file's size"
                           : "is " + std::to_string(bytes) +
                                 " bytes; JSON files of "
                                 "ibrdf are at most 256 MiB");
  }
  std::ifstream in(path);
  if (!in) ThrowError(path, "cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  // Nesting depth and duplicate keys are checked while parsing: a stamp nested 10^5 deep overflowed
  // the stack of later recursive copies, and of two values of one key the library silently keeps the
  // last (numpy and Python keep the last too, other tools the first): a duplicate is an error.
  constexpr int kMaxDepth = 64;
  std::vector<std::set<std::string>> keys;  // per open container; arrays get an empty, unused set
  std::vector<std::string> pointer;         // the key of each open container, for messages
  std::string last_key;
  const auto callback = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start || event == Event::array_start) {
      if (depth >= kMaxDepth) {
        ThrowError(path, "invalid JSON: nested deeper than " + std::to_string(kMaxDepth) + " levels");
      }
      pointer.push_back(keys.empty() ? "" : last_key);
      keys.emplace_back();
    } else if (event == Event::object_end || event == Event::array_end) {
      if (!keys.empty()) keys.pop_back();
      if (!pointer.empty()) pointer.pop_back();
    } else if (event == Event::key) {
      last_key = parsed.get<std::string>();
      if (!keys.empty() && !keys.back().insert(last_key).second) {
        std::string where;
        for (size_t i = 1; i < pointer.size(); ++i) where += "/" + pointer[i];
        ThrowError(path + ": " + where + "/" + last_key, "invalid JSON: the key appears more than once in its object");
      }
    }
    return true;
  };
  // The library's message without its "[json.exception.parse_error.101] " tag, which means nothing to
  // the user: "parse error at line 1, column 1: syntax error while parsing value ...".
  const auto message = [](const nlohmann::json::exception& e) {
    const std::string what = e.what();
    const size_t tag_end = what.rfind("] ", what.find(' '));
    return what.rfind("[json.exception.", 0) == 0 && tag_end != std::string::npos ? what.substr(tag_end + 2) : what;
  };
  try {
    return nlohmann::json::parse(text, callback);
  } catch (const nlohmann::json::parse_error& e) {
    // Turn the byte offset into a line number.
    const size_t offset = std::min<size_t>(e.byte, text.size());
    const long line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(offset), '\n');
    ThrowError(path + ":" + std::to_string(line), "invalid JSON: " + message(e));
  } catch (const nlohmann::json::exception& e) {
    // E.g. a number out of range ("1e400"): the library's message names no file.
    ThrowError(path, "invalid JSON: " + message(e));
  }
}

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path());
    if (!out) ThrowError(path, "cannot write file");
    out << value.dump(2) << "\n";
    if (!out) ThrowError(path, "write failed");
  }
  file.Commit();
}

std::string JsonTypeName(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::object:
      return "an object";
    case nlohmann::json::value_t::array:
      return "an array";
    case nlohmann::json::value_t::string:
      return "a string";
    case nlohmann::json::value_t::boolean:
      return "a boolean";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
    case nlohmann::json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

nlohmann::json ToJson(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

JsonObject::JsonObject(const nlohmann::json& value, std::string file, std::string pointer)
    : value_(&value), file_(std::move(file)), pointer_(std::move(pointer)) {
  if (!value.is_object()) {
    ThrowError(file_ + ": " + (pointer_.empty() ? "/" : pointer_), "expected an object, got " + JsonTypeName(value));
  }
}

bool JsonObject::Has(const std::string& key) const { return value_->contains(key); }

std::string JsonObject::Where(const std::string& key) const {
  if (key.empty()) return file_ + ": " + (pointer_.empty() ? "/" : pointer_);
  return file_ + ": " + pointer_ + "/" + key;
}

const nlohmann::json& JsonObject::Field(const std::string& key) {
  read_.insert(key);
  const auto it = value_->find(key);
  if (it == value_->end()) ThrowError(Where(key), "missing required field");
  return *it;
}

void JsonObject::TypeError(const std::string& key, const std::string& expected) const {
  ThrowError(Where(key), "expected " + expected + ", got " + JsonTypeName(value_->at(key)));
}

double JsonObject::Number(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_number()) TypeError(key, "a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) ThrowError(Where(key), "expected a finite number");
  return x;
}

int JsonObject::Integer(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_number_integer()) TypeError(key, "an integer");
  const bool out_of_range = v.is_number_unsigned() ? v.get<uint64_t>() > uint64_t(std::numeric_limits<int>::max())
                                                   : (v.get<int64_t>() < std::numeric_limits<int>::min() ||
                                                      v.get<int64_t>() > std::numeric_limits<int>::max());
  if (out_of_range) ThrowError(Where(key), "integer out of range, got " + v.dump());
  return v.get<int>();
}

bool JsonObject::Boolean(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_boolean()) TypeError(key, "true or false");
  return v.get<bool>();
}

std::string JsonObject::String(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_string()) TypeError(key, "a string");
  return v.get<std::string>();
}

std::vector<double> JsonObject::Numbers(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_array()) TypeError(key, "an array of numbers");
  std::vector<double> out;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number()) {
      ThrowError(Where(key) + "/" + std::to_string(i), "expected a number, got " + JsonTypeName(v[i]));
    }
    out.push_back(v[i].get<double>());
    if (!std::isfinite(out.back())) {
      ThrowError(Where(key) + "/" + std::to_string(i), "expected a finite number");
    }
  }
  return out;
}

Eigen::Vector3d JsonObject::Vector3(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_array()) TypeError(key, "an array of 3 numbers");
  if (v.size() != 3) ThrowError(Where(key), "expected an array of 3 numbers, got " + std::to_string(v.size()));
  const std::vector<double> numbers = Numbers(key);
  return {numbers[0], numbers[1], numbers[2]};
}

JsonObject JsonObject::Object(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_object()) TypeError(key, "an object");
  return JsonObject(v, file_, pointer_ + "/" + key);
}

std::vector<JsonObject> JsonObject::Objects(const std::string& key) {
  const nlohmann::json& v = Field(key);
  if (!v.is_array()) TypeError(key, "an array of objects");
  std::vector<JsonObject> out;
  for (size_t i = 0; i < v.size(); ++i) {
    out.emplace_back(v[i], file_, pointer_ + "/" + key + "/" + std::to_string(i));
  }
  return out;
}

const nlohmann::json& JsonObject::Raw(const std::string& key) { return Field(key); }

double JsonObject::Number(const std::string& key, double fallback) {
  read_.insert(key);  // an accepted key, listed in unknown-key messages even when absent
  return Has(key) ? Number(key) : fallback;
}
int JsonObject::Integer(const std::string& key, int fallback) {
  read_.insert(key);  // an accepted key, listed in unknown-key messages even when absent
  return Has(key) ? Integer(key) : fallback;
}
bool JsonObject::Boolean(const std::string& key, bool fallback) {
  read_.insert(key);  // an accepted key, listed in unknown-key messages even when absent
  return Has(key) ? Boolean(key) : fallback;
}
std::string JsonObject::String(const std::string& key, const std::string& fallback) {
  read_.insert(key);  // an accepted key, listed in unknown-key messages even when absent
  return Has(key) ? String(key) : fallback;
}

void JsonObject::Finish() const {
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    if (read_.count(it.key())) continue;
    std::string accepted;
    for (const std::string& key : read_) accepted += (accepted.empty() ? "" : ", ") + key;
    ThrowError(Where(it.key()),
               "unknown key \"" + it.key() + "\"" + (accepted.empty() ? "" : " (this object takes: " + accepted + ")"));
  }
}

}  // namespace ibrdf

#include "core/verdict.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"

namespace ibrdf {

const char* VerdictLevelName(VerdictLevel level) {
  switch (level) {
    case VerdictLevel::kOk:
      return "ok";
    case VerdictLevel::kWarn:
      return "warn";
    case VerdictLevel::kFail:
      return "fail";
  }
  UnhandledKind("VerdictLevel", static_cast<int>(level));
}

std::string Verdict::Line() const {
  std::string line =
      check + ": " + VerdictLevelName(level) + (accepted ? " (accepted)" : "") + ": " + measured + "; bound: " + bound;
  if (!remedy.empty() && level != VerdictLevel::kOk) line += "; remedy: " + remedy;
  return line;
}

bool AcceptedChecks::Accepts(const std::string& check) const {
  return std::any_of(names.begin(), names.end(),
                     [&](const std::string& name) { return name == "all" || name == check; });
}

void EnforceVerdicts(std::vector<Verdict>* verdicts, const AcceptedChecks& accepted, const std::string& where) {
  std::string failures;
  for (Verdict& verdict : *verdicts) {
    switch (verdict.level) {
      case VerdictLevel::kOk:
        break;
      case VerdictLevel::kWarn:
        Log(1, "warning: " + verdict.Line());
        break;
      case VerdictLevel::kFail:
        verdict.accepted = accepted.Accepts(verdict.check);
        if (verdict.accepted) {
          Log(1, "warning: accepted by the user: " + verdict.Line());
        } else {
          failures += "\n  " + verdict.Line() + " (an expert may proceed with --accept " + verdict.check + ")";
        }
        break;
    }
  }
  if (!failures.empty()) ThrowError(where, "a result cannot be trusted:" + failures);
}

nlohmann::json VerdictsToJson(const std::vector<Verdict>& verdicts) {
  nlohmann::json json = nlohmann::json::array();
  for (const Verdict& verdict : verdicts) {
    json.push_back({{"check", verdict.check},
                    {"verdict", VerdictLevelName(verdict.level)},
                    {"value", verdict.value},
                    {"measured", verdict.measured},
                    {"bound", verdict.bound},
                    {"remedy", verdict.remedy},
                    {"accepted", verdict.accepted}});
  }
  return json;
}

Verdict MakeVerdict(const std::string& check, double value, const std::string& measured, const std::string& bound,
                    VerdictLevel level, const std::string& remedy) {
  Verdict v;
  v.check = check;
  v.value = value;
  v.measured = measured;
  v.bound = bound;
  v.level = level;
  v.remedy = level == VerdictLevel::kOk ? "" : remedy;
  return v;
}

VerdictLevel WorstVerdict(const std::vector<Verdict>& verdicts) {
  VerdictLevel worst = VerdictLevel::kOk;
  for (const Verdict& verdict : verdicts) {
    if (static_cast<int>(verdict.level) > static_cast<int>(worst)) worst = verdict.level;
  }
  return worst;
}

VerdictLevel VerdictAbove(double value, double warn, double fail) {
  if (!(value <= fail)) return VerdictLevel::kFail;
  if (!(value <= warn)) return VerdictLevel::kWarn;
  return VerdictLevel::kOk;
}

VerdictLevel VerdictBelow(double value, double warn, double fail) {
  if (!(value >= fail)) return VerdictLevel::kFail;
  if (!(value >= warn)) return VerdictLevel::kWarn;
  return VerdictLevel::kOk;
}

}  // namespace ibrdf

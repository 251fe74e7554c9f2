// `ibrdf compare`'s work (truth_comparison.h, CompareFileWithTruth), apart from the comparison itself so
// that the readers' standalone build (fuzz/CMakeLists.txt), which has truth_comparison.cc, needs none of
// the MERL lookup check and the regression behind it.
#include <memory>

#include <nlohmann/json.hpp>

#include "core/merl_brdf.h"
#include "core/merl_format.h"
#include "core/sample_file.h"
#include "reconstruct/reconstruction_error.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf {

CompareOutcome CompareFileWithTruth(const std::string& input, const std::string& truth_path, size_t lookups) {
  const std::unique_ptr<BrdfModel> truth = LoadTruthFile(truth_path);
  CompareOutcome outcome;
  if (IsMerlPath(input)) {
    const MerlLookupCheck check = CheckMerlLookups(ReadMerl(input), *truth, lookups);
    outcome.text = check.Brief() + "\n";
    outcome.json = ToJson(check);
    outcome.json["table"] = input;
  } else {
    const TruthComparison comparison = CompareSampleFileWithTruth(input, *truth);
    outcome.text = ComparisonTable(comparison);
    outcome.brief = comparison.BriefReport();
    outcome.json = ToJson(comparison);
    outcome.json["samples"] = input;
  }
  outcome.json["truth"] = truth_path;
  return outcome;
}

}  // namespace ibrdf

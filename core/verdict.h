// Verdicts over calibration results (docs/verdicts.md): each check of a stage states what it measured,
// the bound it is held to, and `ok`, `warn` or `fail`. A `fail` stops the stage with the measured value,
// the bound and the remedy, unless the user accepted that check by name (`--accept sphere.radius`,
// `--accept all`); an accepted failure is kept in the stage's outputs, marked accepted, so that
// everything downstream can say it was overridden.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/kind.h"

namespace ibrdf {

enum class VerdictLevel {
  kOk,    // within its bound
  kWarn,  // usable, but the result is less certain than it should be (said in every summary)
  kFail,  // not to be trusted: the stage stops unless the check is accepted
  IBRDF_DUMMY_KIND
};
// "ok", "warn", "fail".
const char* VerdictLevelName(VerdictLevel level);

struct Verdict {
  std::string check;  // dotted name, e.g. "sphere.radius", "align.photos_posed" (what --accept takes)
  VerdictLevel level = VerdictLevel::kOk;
  double value = 0.0;     // the measured value
  std::string bound;      // the bound it is held to, in words ("within 0.5x-2x of the stated 0.0250 m")
  std::string measured;   // the value in words, with its unit ("radius 0.0000012 m")
  std::string remedy;     // what to do about a warn or fail ("" for ok)
  bool accepted = false;  // a fail the user accepted (--accept)

  // "sphere.radius: fail: radius 0.0000012 m, bound within 0.5x-2x of the stated 0.025 m; remedy: ..."
  std::string Line() const;
};

// The checks a user accepted (--accept NAME[,NAME...]; "all" accepts every check).
struct AcceptedChecks {
  std::vector<std::string> names;
  bool Accepts(const std::string& check) const;
};

// Marks the accepted failures of `verdicts` and throws Error (naming `where`, one line per unaccepted
// failure, with the remedy and how to accept it) when any failure is left; logs every warn and every
// accepted fail.
void EnforceVerdicts(std::vector<Verdict>* verdicts, const AcceptedChecks& accepted, const std::string& where);

// {"check", "verdict", "value", "measured", "bound", "remedy", "accepted"} each.
nlohmann::json VerdictsToJson(const std::vector<Verdict>& verdicts);
// ok / warn / fail of `value` against an upper bound pair (larger is worse) and a lower bound pair
// (smaller is worse); a value that is not a number fails.
VerdictLevel VerdictAbove(double value, double warn, double fail);
VerdictLevel VerdictBelow(double value, double warn, double fail);

// A verdict of `check` at `level`; the remedy is kept for warn and fail only.
Verdict MakeVerdict(const std::string& check, double value, const std::string& measured, const std::string& bound,
                    VerdictLevel level, const std::string& remedy);

// The worst level over `verdicts` (kOk for none).
VerdictLevel WorstVerdict(const std::vector<Verdict>& verdicts);

}  // namespace ibrdf

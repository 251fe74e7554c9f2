#include "workflow/stage.h"

namespace ibrdf {

const char* StageStatusName(StageStatus status) {
  switch (status) {
    case StageStatus::kRan:
      return "ran";
    case StageStatus::kSkipped:
      return "skipped";
    case StageStatus::kNotApplicable:
      return "not_applicable";
  }
  return "unknown";
}

}  // namespace ibrdf

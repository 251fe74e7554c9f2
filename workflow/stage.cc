#include "workflow/stage.h"

#include "core/kind.h"

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
  UnhandledKind("StageStatus", static_cast<int>(status));
}

}  // namespace ibrdf

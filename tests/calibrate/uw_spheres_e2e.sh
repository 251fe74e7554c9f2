#!/usr/bin/env bash
# Real photos end to end: scripts/uw-spheres (lights calibrated on the chrome sphere, relative
# intensities from the grey sphere, `ibrdf run` with the report) on ../shared/data/uw-photometric-spheres;
# then every output states the relative scale and no stage refused the one before. Skips (exit 77) with
# a message where the data is absent.
# Usage: uw_spheres_e2e.sh IBRDF_BINARY PROJECT_ROOT DATA_DIR OUT_DIR
set -euo pipefail
ibrdf="$1" root="$2" data="$3" out="$4"
if [ ! -f "$data/uw-photometric-spheres/lights.txt" ]; then
  echo "skipped: $data/uw-photometric-spheres is absent (the UW photometric-stereo spheres)"
  exit 77
fi
rm -rf "$out"
IBRDF="$ibrdf" "$root/scripts/uw-spheres" "$out" "$data/uw-photometric-spheres"
/usr/bin/python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
fail = []
summary = json.load(open(f"{out}/run/summary.json"))
if summary.get("intensity_scale") != "relative": fail.append(f"summary.json intensity_scale {summary.get('intensity_scale')}")
for stage, value in summary["stages"].items():
    if value["status"] not in ("ran", "not_applicable", "up_to_date"): fail.append(f"stage {stage}: {value}")
side = json.load(open(f"{out}/run/samples.npy.json"))
if side.get("intensity_scale") != "relative": fail.append("samples.npy.json does not say relative")
recon = json.load(open(f"{out}/run/reconstruction/summary.json"))
if recon.get("intensity_scale") != "relative": fail.append("reconstruction summary does not say relative")
for fit in ("lafortune", "ggx"):
    m = json.load(open(f"{out}/run/reconstruction/{fit}.json"))
    if m.get("scale") != "relative": fail.append(f"{fit}.json has no \"scale\": \"relative\"")
page = open(f"{out}/run/report/index.html").read()
if "relative scale" not in page: fail.append("the report does not say relative scale")
if not os.path.exists(f"{out}/held-out.json"): fail.append("no held-out check")
verdicts = {v["check"]: v for v in json.load(open(f"{out}/lights.calibration.json"))["verdicts"]}
linearity = verdicts.get("lights.response_linearity", {})
if linearity.get("verdict") != "fail" or not linearity.get("accepted"):
    fail.append(f"the grey sphere's cosine exponent should fail lights.response_linearity, accepted: {linearity}")
print("uw-spheres end to end:", "ok" if not fail else "FAILED: " + "; ".join(fail))
sys.exit(1 if fail else 0)
PY

// What every reader of a synthetic session's truth.json ({"format": "ibrdf-truth"}, written by
// synth/synthetic.cc) shares: whether its truth is one material ("material") or spatially varying
// ("material_map", synth --material-map, read by synth/material_map.h), and what the readers that
// compare with one material say of the latter.
#pragma once

#include <string>

namespace ibrdf {

// The message of every single-material comparison refused for a spatially varying truth: no one
// material is the truth of every sample.
inline constexpr char kSpatiallyVaryingTruth[] = "truth is spatially varying: no single-material comparison";

// True for a truth.json ("format" given) that holds a "material_map"; false for a single-material
// truth.json, a material file or a MERL table / RGL .bsdf (by extension, not read). Throws Error as
// ReadJsonFile for an unreadable JSON file.
bool IsSpatiallyVaryingTruth(const std::string& path);

}  // namespace ibrdf

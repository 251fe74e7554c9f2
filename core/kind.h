// Closed sets of kinds (Light::Kind, SampleSpec::Kind, ColourSpace, ...) are handled by `switch`es
// with no `default:`, so that -Wswitch (an error under -Werror) lists every place a new kind must be
// handled; never by `kind == A ? x : y`, which lets a new kind compile and take the wrong branch.
// docs/conventions.md, "Adding a kind", says how to add one; scripts/check-kinds builds with a dummy
// kind in every such enum (the CMake option IBRDF_DUMMY_KINDS) and prints the compiler's list.
#pragma once

namespace ibrdf {

// The last enumerator of every kind enum: a dummy kind in the build that scripts/check-kinds makes,
// nothing otherwise.
#ifdef IBRDF_DUMMY_KINDS
#define IBRDF_DUMMY_KIND kDummyKindForCheck,
#else
#define IBRDF_DUMMY_KIND
#endif

// After a switch over a kind whose cases all return: reached only by a value outside the enum (a bug),
// it throws InternalError naming the enum, never returns a made-up value.
[[noreturn]] void UnhandledKind(const char* enum_name, int value);

}  // namespace ibrdf

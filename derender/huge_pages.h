// Large working buffers backed by transparent huge pages where the kernel allows it (madvise mode).
// The derenderer's buffers (samples, radiance images, decoded photos) are tens of megabytes written
// once; with 4 KiB pages each first touch is a page fault, and on virtual machines those faults cost
// more than the per-pixel work (docs/benchmarks.md, issue 15). Advice only: contents never change.
#pragma once

#include <cstddef>
#include <vector>

namespace ibrdf {

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with huge pages
// (madvise MADV_HUGEPAGE). Ranges under 4 MiB and systems without the call are left alone.
void AdviseHugePages(const void* data, size_t bytes);

// Reserves room for `n` elements in `v` (never shrinks) and advises huge pages for its capacity.
template <typename T>
void ReserveWithHugePages(std::vector<T>* v, size_t n) {
  if (v->capacity() >= n) return;
  v->reserve(n);
  AdviseHugePages(v->data(), v->capacity() * sizeof(T));
}

}  // namespace ibrdf

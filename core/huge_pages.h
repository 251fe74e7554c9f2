// Large working buffers backed by transparent huge pages where the kernel allows it (madvise mode).
// The derenderer's buffers (samples, radiance images, decoded photos) are tens of megabytes written
// once; with 4 KiB pages each first touch is a page fault, and on virtual machines those faults cost
// more than the per-pixel work (docs/benchmarks.md, "Derender"). Advice only: contents never change.
#pragma once

#include <cstddef>
#include <vector>

namespace ibrdf {

// Asks the kernel to back the 2 MiB pages that [data, data + bytes) touches with huge pages (madvise
// MADV_HUGEPAGE), the range widened to whole 2 MiB pages: a huge page needs its whole aligned 2 MiB
// inside one mapping, so the advice reaches the buffer's first and last pages only where the mapping
// holds them (ReserveWithHugePages arranges that); the advice may also cover neighbouring memory of
// the process, which changes nothing but its page size. Ranges under 4 MiB and systems without the call
// are left alone.
void AdviseHugePages(const void* data, size_t bytes);

// The capacity, in elements of `element_bytes`, that ReserveWithHugePages reserves for `n`: n itself
// under 4 MiB; above, rounded up so that the allocation (with malloc's 16-byte header) is a whole number
// of 2 MiB pages, which the kernel places on a 2 MiB boundary: then every page of the buffer, its first
// and last included, can be a huge page (otherwise up to 2 MiB at each end stay 4 KiB pages, each first
// touch a page fault).
size_t HugePageCapacity(size_t n, size_t element_bytes);

// Reserves room for `n` elements in `v` (never shrinks) and advises huge pages for its capacity.
template <typename T>
void ReserveWithHugePages(std::vector<T>* v, size_t n) {
  if (v->capacity() >= n) return;
  v->reserve(HugePageCapacity(n, sizeof(T)));
  AdviseHugePages(v->data(), v->capacity() * sizeof(T));
}

}  // namespace ibrdf

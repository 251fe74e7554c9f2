#include "core/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace ibrdf {

namespace {
constexpr uintptr_t kHuge = uintptr_t(2) << 20;
// MADV_COLLAPSE (Linux 6.1), which glibc's <sys/mman.h> does not define yet; older kernels answer
// EINVAL, which leaves the pages as they were.
#ifdef MADV_COLLAPSE
constexpr int kMadviseCollapse = MADV_COLLAPSE;
#else
constexpr int kMadviseCollapse = 25;
#endif
}  // namespace

void AdviseHugePages(const void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  if (data == nullptr || bytes < 2 * kHuge) return;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes + kHuge - 1) & ~(kHuge - 1);
  // Advice only: an error (an old kernel, THP off, a widened end past the mapping) leaves the pages as
  // they were; the kernel still applies it to the mapped part of the range.
  madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  // malloc wrote its chunk header into the first page before the advice, so that page is a 4 KiB one
  // and the rest of its 2 MiB would fault in 4 KiB at a time (512 faults): make it a huge page now.
  madvise(reinterpret_cast<void*>(begin), kHuge, kMadviseCollapse);
#else
  (void)data;
  (void)bytes;
#endif
}

size_t HugePageCapacity(size_t n, size_t element_bytes) {
  // glibc's chunk header and alignment: the mapping is the request plus at most this, page-rounded.
  constexpr size_t kMallocOverhead = 64;
  const size_t bytes = n * element_bytes;
  if (element_bytes == 0 || bytes < 2 * kHuge) return n;
  const size_t mapping = (bytes + kMallocOverhead + kHuge - 1) & ~(kHuge - 1);
  return (mapping - kMallocOverhead) / element_bytes;
}

}  // namespace ibrdf

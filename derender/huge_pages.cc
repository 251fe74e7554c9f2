#include "derender/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace ibrdf {

namespace {
constexpr uintptr_t kHuge = uintptr_t(2) << 20;
}  // namespace

void AdviseHugePages(const void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  if (data == nullptr || bytes < 2 * kHuge) return;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes + kHuge - 1) & ~(kHuge - 1);
  // Advice only: an error (an old kernel, THP off, a widened end past the mapping) leaves the pages as
  // they were; the kernel still applies it to the mapped part of the range.
  madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
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

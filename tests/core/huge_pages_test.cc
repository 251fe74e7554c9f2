// Huge-page advice for the derenderer's buffers: contents and capacity as reserve() gives them, any
// range accepted, and (where the kernel offers transparent huge pages) the advised range marked
// eligible in /proc/self/smaps.
#include "core/huge_pages.h"

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace ibrdf {
namespace {

TEST(HugePages, ReserveKeepsContentsAndNeverShrinks) {
  std::vector<float> v = {1.0f, 2.0f, 3.0f};
  ReserveWithHugePages(&v, size_t(8) << 20);  // 32 MB
  ASSERT_GE(v.capacity(), size_t(8) << 20);
  EXPECT_EQ(v, (std::vector<float>{1.0f, 2.0f, 3.0f}));
  const float* data = v.data();
  ReserveWithHugePages(&v, 10);  // already room: nothing moves
  EXPECT_EQ(v.data(), data);
  EXPECT_GE(v.capacity(), size_t(8) << 20);
  v.resize(v.capacity(), 4.0f);
  EXPECT_EQ(v.back(), 4.0f);
}

TEST(HugePages, AnyRangeIsAccepted) {
  AdviseHugePages(nullptr, 0);
  AdviseHugePages(nullptr, size_t(1) << 30);
  std::vector<uint8_t> small(100, 7);
  AdviseHugePages(small.data() + 1, small.size() - 1);  // under 4 MiB: left alone
  std::vector<uint8_t> large(size_t(9) << 20, 7);
  AdviseHugePages(large.data() + 3, large.size() - 5);  // unaligned ends
  EXPECT_EQ(small[50], 7);
  EXPECT_EQ(large[large.size() / 2], 7);
}

// The "THPeligible" field of the smaps entry holding `address`; -1 if none says.
int ThpEligible(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const uintptr_t a = reinterpret_cast<uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = a >= begin && a < end;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
  }
  return -1;
}

TEST(HugePages, AdvisedRangeIsEligibleWhereTheKernelOffersThem) {
  std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(enabled, mode);
  if (mode.find("[madvise]") == std::string::npos) {
    GTEST_SKIP() << "transparent huge pages are not in madvise mode here (" << (mode.empty() ? "absent" : mode)
                 << "): the advice has nothing to show";
  }
  std::vector<float> v;
  ReserveWithHugePages(&v, size_t(16) << 20);  // 64 MB
  const float* middle = v.data() + v.capacity() / 2;
  const int eligible = ThpEligible(middle);
  if (eligible < 0) GTEST_SKIP() << "/proc/self/smaps has no THPeligible field on this kernel";
  EXPECT_EQ(eligible, 1);
  // The buffer's first and last pages too (the advice is widened to whole 2 MiB pages), for
  // an odd size and an element that does not divide 2 MiB.
  struct Row {
    char bytes[76];
  };
  std::vector<Row> rows;
  ReserveWithHugePages(&rows, 123457);  // 9.4 MB
  EXPECT_EQ(ThpEligible(rows.data()), 1);
  EXPECT_EQ(ThpEligible(rows.data() + rows.capacity() - 1), 1);
}

// The capacity is n under 4 MiB, and above it at least n and the largest that keeps the allocation
// (with malloc's header) within whole 2 MiB pages.
TEST(HugePages, CapacityFillsWholeHugePages) {
  EXPECT_EQ(HugePageCapacity(1000, 4), 1000u);
  EXPECT_EQ(HugePageCapacity(0, 76), 0u);
  for (size_t n : {size_t(1) << 20, size_t(1234567), size_t(3) << 21}) {
    for (size_t element : {size_t(4), size_t(8), size_t(76)}) {
      constexpr size_t kHuge = size_t(2) << 20;
      const size_t capacity = HugePageCapacity(n, element);
      const size_t whole = (n * element + 64 + kHuge - 1) / kHuge * kHuge;  // whole huge pages for n
      EXPECT_GE(capacity, n);
      EXPECT_LE(capacity * element + 64, whole) << n << " x " << element;
      EXPECT_GT((capacity + 1) * element + 64, whole) << n << " x " << element;
    }
  }
}

}  // namespace
}  // namespace ibrdf

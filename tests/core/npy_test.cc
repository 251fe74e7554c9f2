// Tests of core/npy.h: the one .npy reader refuses every malformed file the fuzzers found with an Error naming
// the file, before allocating for the data.
#include "core/npy.h"

#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ErrorOf;

// A version 1.0 .npy with the given header dict and data bytes.
std::string Npy1(const std::string& dict, const std::string& data) {
  std::string header = dict;
  const size_t total = 10 + header.size() + 1;
  header.append((total + 63) / 64 * 64 - total, ' ');
  header.push_back('\n');
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes.push_back(static_cast<char>(header.size() & 0xff));
  bytes.push_back(static_cast<char>(header.size() >> 8));
  return bytes + header + data;
}

std::string Doubles(const std::vector<double>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
}

void Write(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

class NpyTest : public ::testing::Test {
 protected:
  // The error ReadNpyArray gives for a file holding `bytes`; fails the test unless it names the file.
  std::string ReadError(const std::string& bytes, bool require_finite = false) {
    const std::string path = scratch_ / "a.npy";
    Write(path, bytes);
    std::vector<size_t> shape;
    const std::string message = ErrorOf([&] { ReadNpyArray(path, &shape, require_finite); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    return message;
  }
  testing::ScratchDir scratch_;
};

TEST_F(NpyTest, RoundTrip) {
  const std::string path = scratch_ / "a.npy";
  WriteNpyArray(path, std::vector<double>{1, 2, 3, 4, 5, 6}, {2, 3});
  std::vector<size_t> shape;
  EXPECT_EQ(ReadNpyArray(path, &shape, true), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(shape, (std::vector<size_t>{2, 3}));
}

// `reconstruct --eval` with this shape once segfaulted (the product overflowed to a small count).
TEST_F(NpyTest, ShapeProductOverflowIsAnError) {
  const std::string message =
      ReadError(Npy1("{'descr': '<f8', 'fortran_order': False, 'shape': (6148914691236517206, 3), }", Doubles({1, 2})));
  EXPECT_NE(message.find("overflows"), std::string::npos) << message;
}

// A version 2.0 header length with the high bit set was once sign-extended (basic_string::_M_create).
TEST_F(NpyTest, HugeVersion2HeaderLengthIsAnError) {
  std::string bytes = std::string("\x93NUMPY\x02\x00", 8) + std::string("\x10\x00\x00\x80", 4) + "{}{}{}{}";
  EXPECT_NE(ReadError(bytes).find("header length"), std::string::npos);
}

TEST_F(NpyTest, DuplicateShapeKeyIsAnError) {
  const std::string message =
      ReadError(Npy1("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'shape': (2,), }", Doubles({1, 2})));
  EXPECT_NE(message.find("more than once"), std::string::npos) << message;
}

TEST_F(NpyTest, TrailingGarbageAndShortDataAreErrors) {
  const std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }";
  EXPECT_NE(ReadError(Npy1(dict, Doubles({1, 2, 3}) + "junk")).find("holds"), std::string::npos);
  EXPECT_NE(ReadError(Npy1(dict, Doubles({1, 2}))).find("holds"), std::string::npos);
}

TEST_F(NpyTest, NanIsAnErrorWhenFiniteValuesAreRequired) {
  const std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 3), }";
  const std::string bytes = Npy1(dict, Doubles({std::nan(""), 0, 0}));
  EXPECT_NE(ReadError(bytes, true).find("element 0 is not finite"), std::string::npos);
  const std::string path = scratch_ / "b.npy";
  Write(path, bytes);
  std::vector<size_t> shape;
  EXPECT_EQ(ReadNpyArray(path, &shape, false).size(), 3u);
}

TEST_F(NpyTest, WrongDtypeOrderAndMagicAreErrors) {
  EXPECT_NE(ReadError(Npy1("{'descr': '<f4', 'fortran_order': False, 'shape': (1,), }", "abcd")).find("dtype"),
            std::string::npos);
  EXPECT_NE(ReadError(Npy1("{'descr': '<f8', 'fortran_order': True, 'shape': (1,), }", Doubles({1}))).find("C-order"),
            std::string::npos);
  EXPECT_NE(ReadError("not a numpy file at all").find("magic"), std::string::npos);
  EXPECT_NE(ReadError("").find("magic"), std::string::npos);
}

// A FIFO would block forever; /dev/zero would never end.
TEST_F(NpyTest, NonRegularFilesAreRefused) {
  const std::string fifo = scratch_ / "fifo.npy";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::vector<size_t> shape;
  EXPECT_NE(ErrorOf([&] { ReadNpyArray(fifo, &shape); }).find("not a regular file"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { ReadNpyArray("/dev/zero", &shape); }).find("/dev/zero"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { ReadNpyArray(scratch_ / "missing.npy", &shape); }).find("does not exist"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf

// Tests of core/sample_file.h: BRDF sample files are NumPy .npy structured arrays that round-trip,
// that NumPy itself loads (and writes) with the documented dtype, and whose damage is detected.
#include "core/sample_file.h"

#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/npy.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

constexpr char kPython[] = "/usr/bin/python3";

// Three rows with distinct, exactly representable values in every field, each a valid sample (unit
// directions, angles in range, non-negative BRDF and sigma).
std::vector<BrdfSample> TestSamples() {
  std::vector<BrdfSample> samples(3);
  for (size_t r = 0; r < samples.size(); ++r) {
    BrdfSample& s = samples[r];
    const float base = static_cast<float>(r);
    for (int k = 0; k < 3; ++k) {
      s.wi[k] = k == 2 - static_cast<int>(r) ? 1.0f : 0.0f;
      s.wo[k] = k == static_cast<int>(r) ? 1.0f : 0.0f;
      s.brdf[k] = 0.25f * (k + 1) + base;
      s.sigma[k] = 0.0625f * (k + 1);
    }
    s.theta_i = 0.25f + 0.25f * base;
    s.theta_e = 0.125f + 0.25f * base;
    s.delta_phi = -0.5f - base;
    s.image = static_cast<uint32_t>(7 * r + 1);
    s.pixel[0] = static_cast<uint32_t>(640 + r);
    s.pixel[1] = static_cast<uint32_t>(480 + 2 * r);
    s.exposures = static_cast<uint8_t>(r + 1);
  }
  samples[1].valid[2] = 0;  // a blue channel below the signal floor
  return samples;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Replaces `from` by `to` in the header of .npy 1.0 `bytes` and updates the header length field.
std::string EditHeader(const std::string& bytes, const std::string& from, const std::string& to) {
  const size_t header_length = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  std::string header = bytes.substr(10, header_length);
  const size_t at = header.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at == std::string::npos) return bytes;
  header.replace(at, from.size(), to);
  std::string edited = bytes.substr(0, 8);
  edited.push_back(static_cast<char>(header.size() & 0xff));
  edited.push_back(static_cast<char>(header.size() >> 8));
  return edited + header + bytes.substr(10 + header_length);
}

// A fresh folder per test.
class SampleFileTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = scratch_.str(); }
  testing::ScratchDir scratch_;
  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  // Expects ReadSamples to throw an Error naming the file.
  void ExpectReadError(const std::string& path) const {
    try {
      ReadSamples(path);
      ADD_FAILURE() << "expected an Error reading " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "expected an ibrdf::Error reading " << path << ", got: " << e.what();
    }
  }

  std::string dir_;
};

void ExpectSameSamples(const std::vector<BrdfSample>& a, const std::vector<BrdfSample>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::memcmp(&a[i], &b[i], sizeof(BrdfSample)), 0) << "row " << i;
  }
}

TEST(BrdfSample, LayoutMatchesTheDtype) {
  EXPECT_EQ(sizeof(BrdfSample), 76u);
  EXPECT_EQ(offsetof(BrdfSample, valid), 72u);
  EXPECT_EQ(offsetof(BrdfSample, exposures), 75u);
  EXPECT_EQ(offsetof(BrdfSample, theta_i), 24u);
  EXPECT_EQ(offsetof(BrdfSample, brdf), 36u);
  EXPECT_EQ(offsetof(BrdfSample, image), 60u);
  EXPECT_EQ(offsetof(BrdfSample, pixel), 64u);
}

TEST(SidecarPath, AppendsJson) { EXPECT_EQ(SidecarPath("out/samples.npy"), "out/samples.npy.json"); }

// Every byte of every row survives a write and a read.
TEST_F(SampleFileTest, RoundTrip) {
  const std::vector<BrdfSample> samples = TestSamples();
  WriteSamples(Path("samples.npy"), samples);
  ExpectSameSamples(ReadSamples(Path("samples.npy")), samples);
}

TEST_F(SampleFileTest, EmptyRoundTrip) {
  WriteSamples(Path("empty.npy"), {});
  EXPECT_TRUE(ReadSamples(Path("empty.npy")).empty());
}

// Files larger than ReadSamples' read buffer (8192 rows): every row round-trips, and an invalid row
// far into the file is named by its index.
TEST_F(SampleFileTest, ManyRowsRoundTripAndLateErrorsNameTheRow) {
  const std::vector<BrdfSample> pattern = TestSamples();
  std::vector<BrdfSample> samples;
  for (size_t i = 0; i < 20001; ++i) {
    BrdfSample s = pattern[i % pattern.size()];
    s.pixel[0] = static_cast<uint32_t>(i);  // every row distinct
    samples.push_back(s);
  }
  WriteSamples(Path("many.npy"), samples);
  ExpectSameSamples(ReadSamples(Path("many.npy")), samples);
  samples[19000].theta_i = 3.0f;
  WriteSamples(Path("many.npy"), samples);
  const std::string message = testing::ErrorOf([&] { ReadSamples(Path("many.npy")); });
  EXPECT_NE(message.find(Path("many.npy") + ": sample 19000: theta_i"), std::string::npos) << message;
}

// A version 1 file (72-byte rows) larger than the read buffer: each row is the version 2 row's prefix,
// every channel valid, exposures 0.
TEST_F(SampleFileTest, ManyVersion1RowsAreConverted) {
  std::vector<BrdfSample> samples;
  for (size_t i = 0; i < 17000; ++i) {
    BrdfSample s = TestSamples()[i % 3];
    s.pixel[1] = static_cast<uint32_t>(i);
    samples.push_back(s);
  }
  std::string rows;
  for (const BrdfSample& s : samples) rows.append(reinterpret_cast<const char*>(&s), 72);
  WriteNpy(Path("v1.npy"), BrdfSampleDtypeVersion1(), {samples.size()}, 72, rows.data(), rows.size());
  const std::vector<BrdfSample> read = ReadSamples(Path("v1.npy"));
  ASSERT_EQ(read.size(), samples.size());
  for (size_t i = 0; i < read.size(); ++i) {
    ASSERT_EQ(std::memcmp(&read[i], &samples[i], 72), 0) << "row " << i;
    ASSERT_TRUE(read[i].AllValid()) << "row " << i;
    ASSERT_EQ(read[i].exposures, 0) << "row " << i;
  }
}

// The .npy 1.0 layout: magic, version, little-endian header length, a header padded to a multiple of
// 64 bytes and ending in a newline, holding our dtype and the row count, then exactly the rows.
TEST_F(SampleFileTest, FileIsNpyVersion1) {
  WriteSamples(Path("samples.npy"), TestSamples());
  const std::string bytes = ReadBytes(Path("samples.npy"));
  ASSERT_GT(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), std::string("\x93NUMPY"));
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const size_t header_length = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  EXPECT_EQ((10 + header_length) % 64, 0u);
  ASSERT_EQ(bytes.size(), 10 + header_length + 3 * sizeof(BrdfSample));
  const std::string header = bytes.substr(10, header_length);
  EXPECT_EQ(header.back(), '\n');
  EXPECT_NE(header.find(std::string("'descr': ") + BrdfSampleDtype()), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
  EXPECT_NE(header.find("'shape': (3,)"), std::string::npos) << header;
  // Field order of the dtype as documented.
  const std::string dtype = BrdfSampleDtype();
  EXPECT_LT(dtype.find("'wi'"), dtype.find("'wo'"));
  EXPECT_LT(dtype.find("'delta_phi'"), dtype.find("'brdf'"));
  EXPECT_LT(dtype.find("'image'"), dtype.find("'pixel'"));
}

// Writing is atomic: only the final file remains.
TEST_F(SampleFileTest, WriteLeavesNoTemporaryFile) {
  WriteSamples(Path("samples.npy"), TestSamples());
  WriteSamples(Path("samples.npy"), {});
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "samples.npy");
  }
  EXPECT_EQ(files, 1u);
}

// A file cut short (a crashed copy) does not hold the rows its header promises.
TEST_F(SampleFileTest, TruncatedFileIsAnError) {
  const std::string path = Path("samples.npy");
  WriteSamples(path, TestSamples());
  fs::resize_file(path, fs::file_size(path) - 10);
  ExpectReadError(path);
  fs::resize_file(path, 40);  // inside the header
  ExpectReadError(path);
  fs::resize_file(path, 4);  // inside the magic
  ExpectReadError(path);
}

// A header claiming more, or fewer, rows than the data holds.
TEST_F(SampleFileTest, HeaderLyingAboutRowCountIsAnError) {
  const std::string path = Path("samples.npy");
  WriteSamples(path, TestSamples());
  const std::string bytes = ReadBytes(path);
  for (const char* lie : {"'shape': (4,)", "'shape': (2,)", "'shape': (30,)"}) {
    WriteBytes(path, EditHeader(bytes, "'shape': (3,)", lie));
    ExpectReadError(path);
  }
  // The unedited bytes still read (the edit, not the rewrite, is what fails).
  WriteBytes(path, EditHeader(bytes, "'shape': (3,)", "'shape': (3,)"));
  EXPECT_EQ(ReadSamples(path).size(), 3u);
}

// Row counts whose byte size overflows: (2^61 + 3) * 72 wraps modulo 2^64 to exactly the 216 bytes
// present, and a 25-digit count does not fit 64 bits. Both must be an Error, not an allocation failure.
TEST_F(SampleFileTest, HugeRowCountIsAnError) {
  const std::string path = Path("samples.npy");
  WriteSamples(path, TestSamples());
  const std::string bytes = ReadBytes(path);
  for (const char* lie : {"'shape': (2305843009213693955,)", "'shape': (9999999999999999999999999,)"}) {
    WriteBytes(path, EditHeader(bytes, "'shape': (3,)", lie));
    ExpectReadError(path);
  }
}

// Files that are not ours: another dtype, a 2-D shape, no .npy magic, no file at all.
TEST_F(SampleFileTest, ForeignFilesAreErrors) {
  const std::string path = Path("samples.npy");
  WriteSamples(path, TestSamples());
  const std::string bytes = ReadBytes(path);

  WriteBytes(path, EditHeader(bytes, "('wi', '<f4'", "('wi', '>f4'"));  // big-endian
  ExpectReadError(path);
  WriteBytes(path, EditHeader(bytes, "'fortran_order': False", "'fortran_order': True"));
  ExpectReadError(path);

  WriteBytes(path, EditHeader(bytes, "'shape': (3,)", "'shape': (3, 1)"));
  ExpectReadError(path);

  WriteBytes(path, "just some text, not an array");
  ExpectReadError(path);

  ExpectReadError(Path("absent.npy"));
}

bool HaveNumpy() {
  if (!fs::exists(kPython)) return false;
  return std::system((std::string(kPython) + " -c 'import numpy' > /dev/null 2>&1").c_str()) == 0;
}

// Runs `script` with /usr/bin/python3, the file path as sys.argv[1]; true when it exits 0.
bool RunPython(const std::string& script, const std::string& path) {
  const std::string command = std::string(kPython) + " -c \"" + script + "\" '" + path + "'";
  return std::system(command.c_str()) == 0;
}

// NumPy loads the file in one call with the right shape, dtype size and field values.
TEST_F(SampleFileTest, NumpyLoadsTheFile) {
  if (!HaveNumpy()) GTEST_SKIP() << kPython << " with numpy is not installed";
  const std::string path = Path("samples.npy");
  WriteSamples(path, TestSamples());
  const std::string script =
      "import sys, numpy\n"
      "s = numpy.load(sys.argv[1])\n"
      "assert s.shape == (3,), s.shape\n"
      "assert s.dtype.itemsize == 76, s.dtype\n"
      "assert s['valid'].shape == (3, 3) and s['valid'][1].tolist() == [1, 1, 0], s['valid']\n"
      "assert s['brdf'].shape == (3, 3), s['brdf'].shape\n"
      "assert s['brdf'][1, 2] == 1.75, s['brdf'][1]\n"
      "assert list(s['wi'][2]) == [1, 0, 0], s['wi'][2]\n"
      "assert s['delta_phi'][1] == -1.5, s['delta_phi']\n"
      "assert s['image'][2] == 15, s['image']\n"
      "assert list(s['pixel'][2]) == [642, 484], s['pixel']\n"
      "assert s['sigma'][0, 2] == 0.1875, s['sigma'][0]\n";
  EXPECT_TRUE(RunPython(script, path));
}

// ReadSamples reads a version 1 file (72-byte rows, no per-channel validity) that NumPy wrote: every
// channel valid, exposures not recorded.
TEST_F(SampleFileTest, ReadsFileWrittenByNumpy) {
  if (!HaveNumpy()) GTEST_SKIP() << kPython << " with numpy is not installed";
  const std::string path = Path("from_numpy.npy");
  const std::string script =
      "import sys, numpy\n"
      "dt = numpy.dtype([('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), "
      "('theta_e', '<f4'), ('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), "
      "('image', '<u4'), ('pixel', '<u4', (2,))])\n"
      "a = numpy.zeros(2, dtype=dt)\n"
      "a['wi'][:] = [0, 0, 1]\n"
      "a['wo'][:] = [0, 0, 1]\n"
      "a['brdf'][1] = [0.25, 0.5, 0.75]\n"
      "a['theta_e'][1] = 1.5\n"
      "a['pixel'][1] = [3, 4]\n"
      "a['image'][0] = 9\n"
      "numpy.save(sys.argv[1], a)\n";
  ASSERT_TRUE(RunPython(script, path));
  const std::vector<BrdfSample> samples = ReadSamples(path);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[1].brdf[0], 0.25f);
  EXPECT_EQ(samples[1].brdf[2], 0.75f);
  EXPECT_EQ(samples[1].theta_e, 1.5f);
  EXPECT_EQ(samples[1].pixel[0], 3u);
  EXPECT_EQ(samples[1].pixel[1], 4u);
  EXPECT_EQ(samples[0].image, 9u);
  for (const BrdfSample& s : samples) {
    EXPECT_TRUE(s.AllValid());
    EXPECT_EQ(s.exposures, 0);
  }
}

// ReadSamples reads a version 2 file that NumPy wrote, per-channel validity included, and refuses a row
// without any valid channel or with a flag other than 0 or 1.
TEST_F(SampleFileTest, ReadsValidityWrittenByNumpy) {
  if (!HaveNumpy()) GTEST_SKIP() << kPython << " with numpy is not installed";
  const std::string path = Path("valid_from_numpy.npy");
  const std::string script =
      "import sys, numpy\n"
      "dt = numpy.dtype([('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), "
      "('theta_e', '<f4'), ('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), "
      "('image', '<u4'), ('pixel', '<u4', (2,)), ('valid', 'u1', (3,)), ('exposures', 'u1')])\n"
      "a = numpy.zeros(2, dtype=dt)\n"
      "a['wi'][:] = [0, 0, 1]\n"
      "a['wo'][:] = [0, 0, 1]\n"
      "a['valid'][0] = [1, 1, 1]\n"
      "a['valid'][1] = [1, 0, 0]\n"
      "a['exposures'] = [3, 1]\n"
      "numpy.save(sys.argv[1], a)\n";
  ASSERT_TRUE(RunPython(script, path));
  const std::vector<BrdfSample> samples = ReadSamples(path);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_TRUE(samples[0].AllValid());
  EXPECT_TRUE(samples[1].Valid(0));
  EXPECT_FALSE(samples[1].Valid(1));
  EXPECT_FALSE(samples[1].Valid(2));
  EXPECT_EQ(samples[0].exposures, 3);
}

// Sample files with NaN or infinite values, angles out of range, |wi| != 1, negative sigma or
// BRDF were read silently (and NaN reached `check` and `compare` outputs). Each is now an Error naming
// the file and the first bad sample.
TEST_F(SampleFileTest, InvalidSamplesAreErrors) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::pair<std::function<void(BrdfSample*)>, std::string>> cases = {
      {[&](BrdfSample* s) { s->brdf[1] = nan; }, "brdf[1]"},
      {[&](BrdfSample* s) { s->wi[0] = inf; }, "not finite"},
      {[&](BrdfSample* s) { s->theta_i = 7.0f; }, "theta_i"},
      {[&](BrdfSample* s) { s->theta_e = -0.5f; }, "theta_e"},
      {[&](BrdfSample* s) { s->delta_phi = 4.0f; }, "delta_phi"},
      {[&](BrdfSample* s) { s->wi[2] = 1.5f; }, "|wi|"},
      {[&](BrdfSample* s) { s->wo[0] = 0.5f; }, "|wo|"},
      {[&](BrdfSample* s) { s->sigma[0] = -1.0f; }, "sigma[0]"},
      {[&](BrdfSample* s) { s->brdf[2] = -0.5f; }, "brdf[2]"},
      {[&](BrdfSample* s) { s->valid[0] = s->valid[1] = s->valid[2] = 0; }, "no channel is valid"},
      {[&](BrdfSample* s) { s->valid[1] = 7; }, "valid flag"},
  };
  const std::string path = Path("bad.npy");
  for (const auto& [spoil, expected] : cases) {
    std::vector<BrdfSample> samples = TestSamples();
    spoil(&samples[1]);
    WriteSamples(path, samples);
    const std::string message = testing::ErrorOf([&] { ReadSamples(path); });
    EXPECT_NE(message.find(path + ": sample 1: "), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << expected << ": " << message;
  }
}

// 20001 distinct rows (more than one read buffer of ReadSamples' 8192 rows).
std::vector<BrdfSample> ManySamples() {
  const std::vector<BrdfSample> pattern = TestSamples();
  std::vector<BrdfSample> samples;
  for (size_t i = 0; i < 20001; ++i) {
    BrdfSample s = pattern[i % pattern.size()];
    s.pixel[0] = static_cast<uint32_t>(i);
    samples.push_back(s);
  }
  return samples;
}

// The streamed writer's file is byte for byte WriteSamples' for the same rows, whatever the runs they
// come in (empty runs included) and whatever the count's digits (the header's count is patched in place).
TEST_F(SampleFileTest, StreamedFileIsByteIdenticalToWriteSamples) {
  const std::vector<BrdfSample> all = ManySamples();
  for (const size_t count : {size_t(0), size_t(1), size_t(9), size_t(10), size_t(12345), all.size()}) {
    const std::vector<BrdfSample> samples(all.begin(), all.begin() + count);
    WriteSamples(Path("whole.npy"), samples);
    {
      SampleFileWriter writer(Path("streamed.npy"));
      size_t done = 0;
      for (size_t run = 0; done < count; run = (run + 7) % 4000) {
        const size_t n = std::min(run, count - done);
        writer.Append(samples.data() + done, n);
        done += n;
      }
      EXPECT_EQ(writer.rows(), count);
      writer.Finish();
    }
    const std::string whole = ReadBytes(Path("whole.npy"));
    ASSERT_EQ(ReadBytes(Path("streamed.npy")), whole) << count << " rows";
    ExpectSameSamples(ReadSamples(Path("streamed.npy")), samples);
  }
}

// The chunked reader hands over every row once, in file order, in chunks of the size asked for (the
// last one shorter), each with its first row's index; version 1 rows converted as ReadSamples does.
TEST_F(SampleFileTest, ChunkedReaderGivesEveryRowOnceInOrder) {
  const std::vector<BrdfSample> samples = ManySamples();
  WriteSamples(Path("many.npy"), samples);
  std::vector<BrdfSample> read;
  std::vector<uint64_t> firsts;
  const uint64_t rows = ForEachSampleChunk(Path("many.npy"), 5000, [&](const BrdfSample* chunk, size_t n, uint64_t first) {
    EXPECT_EQ(first, read.size());
    EXPECT_LE(n, 5000u);
    firsts.push_back(first);
    read.insert(read.end(), chunk, chunk + n);
  });
  EXPECT_EQ(rows, samples.size());
  EXPECT_EQ(firsts, (std::vector<uint64_t>{0, 5000, 10000, 15000, 20000}));
  ExpectSameSamples(read, samples);
  std::string v1;
  for (const BrdfSample& s : samples) v1.append(reinterpret_cast<const char*>(&s), 72);
  WriteNpy(Path("v1.npy"), BrdfSampleDtypeVersion1(), {samples.size()}, 72, v1.data(), v1.size());
  read.clear();
  ForEachSampleChunk(Path("v1.npy"), 3000,
                     [&](const BrdfSample* chunk, size_t n, uint64_t) { read.insert(read.end(), chunk, chunk + n); });
  ExpectSameSamples(read, ReadSamples(Path("v1.npy")));
  WriteSamples(Path("empty.npy"), {});
  size_t calls = 0;
  EXPECT_EQ(ForEachSampleChunk(Path("empty.npy"), 10, [&](const BrdfSample*, size_t, uint64_t) { ++calls; }), 0u);
  EXPECT_EQ(calls, 0u);
}

// A bad row stops the chunked reader with an Error naming the file and the row, before its chunk is
// handed over; the chunks before it were whole and valid.
TEST_F(SampleFileTest, ChunkedReaderNamesTheFileAndTheBadRow) {
  std::vector<BrdfSample> samples = ManySamples();
  samples[17003].delta_phi = 5.0f;
  WriteSamples(Path("bad.npy"), samples);
  uint64_t handed = 0;
  const std::string message = testing::ErrorOf([&] {
    ForEachSampleChunk(Path("bad.npy"), 1000, [&](const BrdfSample*, size_t n, uint64_t) { handed += n; });
  });
  EXPECT_NE(message.find(Path("bad.npy") + ": sample 17003: delta_phi"), std::string::npos) << message;
  EXPECT_EQ(handed, 17000u);
  // A file cut short: the header's count no longer matches its rows.
  std::string bytes = ReadBytes(Path("bad.npy"));
  WriteBytes(Path("cut.npy"), bytes.substr(0, bytes.size() - 10));
  const std::string cut = testing::ErrorOf([&] { ForEachSampleChunk(Path("cut.npy"), 1000, [](const BrdfSample*, size_t, uint64_t) {}); });
  EXPECT_NE(cut.find(Path("cut.npy")), std::string::npos) << cut;
}

}  // namespace
}  // namespace ibrdf

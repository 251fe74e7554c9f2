// Tests of core/json_reader.h: strict JSON reading whose errors name the file, the JSON pointer of the
// field or the line of a syntax error.
#include "core/json_reader.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using nlohmann::json;

constexpr char kFile[] = "config/test.json";

// Expects `call` to throw an Error whose message contains every one of `parts`.
template <typename Call>
void ExpectError(Call call, std::initializer_list<std::string> parts) {
  try {
    call();
    ADD_FAILURE() << "expected an Error containing " << *parts.begin();
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
  }
}

const json kDocument = json::parse(R"({
  "name": "sphere",
  "count": 3,
  "ratio": 0.5,
  "flag": true,
  "light": {"intensity": [1, 2, 3], "kind": "point"},
  "params": [1.5, 2, -3],
  "photos": [{"file": "a.png"}, {"file": 7}]
})");

// Well-typed fields read back; optional fields fall back only when absent.
TEST(JsonObject, ReadsTypedFields) {
  JsonObject root(kDocument, kFile);
  EXPECT_EQ(root.String("name"), "sphere");
  EXPECT_EQ(root.Integer("count"), 3);
  EXPECT_EQ(root.Number("count"), 3.0);  // an integer is a number
  EXPECT_EQ(root.Number("ratio"), 0.5);
  EXPECT_TRUE(root.Boolean("flag"));
  JsonObject light = root.Object("light");
  EXPECT_EQ(light.Vector3("intensity"), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(light.String("kind"), "point");
  EXPECT_NO_THROW(light.Finish());
  EXPECT_EQ(root.Numbers("params"), (std::vector<double>{1.5, 2, -3}));
  EXPECT_EQ(root.Objects("photos").size(), 2u);
  EXPECT_NO_THROW(root.Finish());
  EXPECT_EQ(root.Number("absent", 7.5), 7.5);
  EXPECT_EQ(root.Integer("absent", 4), 4);
  EXPECT_FALSE(root.Boolean("absent", false));
  EXPECT_EQ(root.String("absent", "x"), "x");
  EXPECT_EQ(root.Number("ratio", 9.0), 0.5);
  EXPECT_TRUE(root.Has("name"));
  EXPECT_FALSE(root.Has("absent"));
}

TEST(JsonObject, WhereNamesFileAndPointer) {
  JsonObject root(kDocument, kFile);
  EXPECT_EQ(root.Where("name"), "config/test.json: /name");
  EXPECT_EQ(root.Object("light").Where("intensity"), "config/test.json: /light/intensity");
  EXPECT_EQ(root.Objects("photos")[1].Where("file"), "config/test.json: /photos/1/file");
}

// A wrongly typed field names the file, the field's pointer, what was expected and what was found.
TEST(JsonObject, TypeErrorsNameThePointer) {
  JsonObject root(kDocument, kFile);
  ExpectError([&] { root.Number("name"); }, {kFile, "/name", "a number", "a string"});
  ExpectError([&] { root.String("count"); }, {kFile, "/count", "a string", "a number"});
  ExpectError([&] { root.Integer("ratio"); }, {kFile, "/ratio", "an integer"});
  ExpectError([&] { root.Boolean("count"); }, {kFile, "/count"});
  ExpectError([&] { root.Object("name"); }, {kFile, "/name", "an object"});
  ExpectError([&] { root.Objects("light"); }, {kFile, "/light", "an array"});
  JsonObject light = root.Object("light");
  ExpectError([&] { light.Number("intensity"); }, {kFile, "/light/intensity", "a number", "an array"});
  ExpectError([&] { light.Vector3("kind"); }, {kFile, "/light/kind", "an array of 3 numbers", "a string"});
  JsonObject photo = root.Objects("photos")[1];
  ExpectError([&] { photo.String("file"); }, {kFile, "/photos/1/file", "a string", "a number"});
}

// Optional fields that are present but wrongly typed are still errors.
TEST(JsonObject, OptionalFieldsAreTypeChecked) {
  JsonObject root(kDocument, kFile);
  ExpectError([&] { root.Number("name", 1.0); }, {kFile, "/name"});
  ExpectError([&] { root.Integer("ratio", 1); }, {kFile, "/ratio"});
  ExpectError([&] { root.Boolean("count", false); }, {kFile, "/count"});
  ExpectError([&] { root.String("flag", ""); }, {kFile, "/flag"});
}

// An element of the wrong type inside an array is named by its index.
TEST(JsonObject, ArrayElementErrorsNameTheIndex) {
  const json value = json::parse(R"({"v": [1, "two", 3], "w": [1, 2], "u": [1, 2, null]})");
  JsonObject root(value, kFile);
  ExpectError([&] { root.Numbers("v"); }, {kFile, "/v/1", "a number", "a string"});
  ExpectError([&] { root.Vector3("v"); }, {kFile, "/v/1"});
  ExpectError([&] { root.Vector3("w"); }, {kFile, "/w", "an array of 3 numbers"});
  ExpectError([&] { root.Vector3("u"); }, {kFile, "/u/2", "null"});
}

TEST(JsonObject, MissingRequiredFieldIsNamed) {
  JsonObject root(kDocument, kFile);
  ExpectError([&] { root.Number("radius"); }, {kFile, "/radius", "missing"});
  JsonObject light = root.Object("light");
  ExpectError([&] { light.Vector3("position"); }, {kFile, "/light/position", "missing"});
}

// Finish() rejects keys that were never read, naming the key and listing what the object accepts.
TEST(JsonObject, UnknownKeyIsNamed) {
  const json value = json::parse(R"({"radius": 1.0, "raduis": 2.0})");
  JsonObject root(value, kFile);
  root.Number("radius");
  ExpectError([&] { root.Finish(); }, {kFile, "/raduis", "unknown key", "radius"});

  const json nested = json::parse(R"({"light": {"kind": "point", "intensty": [1, 1, 1]}})");
  JsonObject outer(nested, kFile);
  JsonObject light = outer.Object("light");
  light.String("kind");
  ExpectError([&] { light.Finish(); }, {kFile, "/light/intensty", "unknown key"});
}

// A present optional key that was read counts as read.
TEST(JsonObject, OptionalReadsCountAsRead) {
  const json value = json::parse(R"({"gain": 2.0})");
  JsonObject root(value, kFile);
  root.Number("gain", 1.0);
  root.Number("exposure_s", 1.0);
  EXPECT_NO_THROW(root.Finish());
}

// The unknown-key message lists every key the object accepts, optional ones included even when they
// are absent: a misspelt optional key ("descripton") is the usual mistake, and the list must show
// the right spelling.
TEST(JsonObject, UnknownKeyErrorListsOptionalKeys) {
  const json value = json::parse(R"({"model": "lambertian", "descripton": "grey"})");
  JsonObject root(value, kFile);
  root.String("model");
  root.String("description", "");
  root.Number("gain", 1.0);
  ExpectError([&] { root.Finish(); }, {kFile, "/descripton", "model", "description", "gain"});
}

// Only objects can be read field by field.
TEST(JsonObject, NonObjectIsAnError) {
  ExpectError([] { JsonObject(json::array({1, 2}), kFile); }, {kFile, "expected an object", "an array"});
  ExpectError([] { JsonObject(json("text"), kFile, "/camera"); }, {kFile, "/camera", "a string"});
}

// An integer field holding a value int cannot represent is an error, not a silently wrapped number.
TEST(JsonObject, IntegerOutOfRangeIsAnError) {
  const json value = json::parse(R"({"width": 5000000000, "height": -5000000000})");
  JsonObject root(value, kFile);
  ExpectError([&] { root.Integer("width"); }, {kFile, "/width"});
  ExpectError([&] { root.Integer("height"); }, {kFile, "/height"});
}

TEST(JsonTypeName, NamesEveryType) {
  EXPECT_EQ(JsonTypeName(json(nullptr)), "null");
  EXPECT_EQ(JsonTypeName(json::object()), "an object");
  EXPECT_EQ(JsonTypeName(json::array()), "an array");
  EXPECT_EQ(JsonTypeName(json("s")), "a string");
  EXPECT_EQ(JsonTypeName(json(true)), "a boolean");
  EXPECT_EQ(JsonTypeName(json(1)), "a number");
  EXPECT_EQ(JsonTypeName(json(1u)), "a number");
  EXPECT_EQ(JsonTypeName(json(1.5)), "a number");
}

TEST(ToJson, VectorIsAnArrayOfThree) {
  EXPECT_EQ(ToJson(Eigen::Vector3d(1.5, -2, 0.125)), json::parse("[1.5, -2.0, 0.125]"));
}

// A folder per test for the file-based tests.
class JsonFileTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = scratch_.str(); }
  testing::ScratchDir scratch_;
  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  std::string dir_;
};

// A syntax error names the file and the line it is on.
TEST_F(JsonFileTest, SyntaxErrorNamesTheLine) {
  const std::string path = Path("broken.json");
  std::ofstream(path) << "{\n  \"a\": 1,\n  \"b\": 2\n  \"c\": 3\n}\n";  // missing comma after line 3
  try {
    ReadJsonFile(path);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path + ":4"), std::string::npos) << message;
  }
  const std::string first_line = Path("first_line.json");
  std::ofstream(first_line) << "{ \"a\": tru }\n";
  ExpectError([&] { ReadJsonFile(first_line); }, {first_line + ":1"});
}

TEST_F(JsonFileTest, MissingFileIsNamed) {
  const std::string path = Path("absent.json");
  ExpectError([&] { ReadJsonFile(path); }, {path});
}

TEST_F(JsonFileTest, EmptyFileIsAnError) {
  const std::string path = Path("empty.json");
  std::ofstream{path};
  ExpectError([&] { ReadJsonFile(path); }, {path});
}

// Not a regular file (a FIFO, /dev/zero, a folder): one line naming the path, no hang, no runaway memory.
TEST_F(JsonFileTest, NonRegularFileIsRefused) {
  const std::string fifo = Path("pipe.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ExpectError([&] { ReadJsonFile(fifo); }, {fifo, "not a regular file"});
  ExpectError([&] { ReadJsonFile("/dev/zero"); }, {"/dev/zero", "not a regular file"});
  ExpectError([&] { ReadJsonFile(dir_); }, {dir_, "not a regular file"});
}

// A number JSON cannot hold ('1e400') is an Error naming the file, not the library's bare message.
TEST_F(JsonFileTest, NumberOverflowNamesTheFile) {
  const std::string path = Path("overflow.json");
  std::ofstream(path) << "{\"exposure_s\": 1e400}\n";
  ExpectError([&] { ReadJsonFile(path); }, {path, "invalid JSON"});
}

// A file that is not JSON at all (a PNG given where a JSON file was asked for): the line and the
// parser's reason, without the library's "[json.exception.parse_error.101]" tag.
TEST_F(JsonFileTest, NotJsonGivesTheReasonWithoutTheLibrarysTag) {
  const std::string path = Path("photo.png");
  std::ofstream(path) << "\x89PNG\r\n";
  try {
    ReadJsonFile(path);
    ADD_FAILURE() << "expected an Error for " << path;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path + ":1"), std::string::npos) << message;
    EXPECT_NE(message.find("invalid JSON: parse error at line 1"), std::string::npos) << message;
    EXPECT_EQ(message.find("json.exception"), std::string::npos) << message;
  }
}

// WriteJsonFile round-trips through ReadJsonFile and leaves no temporary file behind.
TEST_F(JsonFileTest, WriteReadRoundTrip) {
  const std::string path = Path("out.json");
  WriteJsonFile(path, kDocument);
  EXPECT_EQ(ReadJsonFile(path), kDocument);
  WriteJsonFile(path, json{{"replaced", true}});
  EXPECT_EQ(ReadJsonFile(path), (json{{"replaced", true}}));
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "out.json");
  }
  EXPECT_EQ(files, 1u);
}

// Of two values of one key the JSON library keeps the last silently; ibrdf makes it an Error naming the key.
TEST_F(JsonFileTest, DuplicateKeyIsAnError) {
  const std::string path = Path("twice.json");
  std::ofstream(path) << "{\"light\": {\"intensity\": 1, \"intensity\": 2}}\n";
  ExpectError([&] { ReadJsonFile(path); }, {path, "/light/intensity", "more than once"});
  // The same key in two different objects is fine.
  std::ofstream(path) << "{\"a\": {\"x\": 1}, \"b\": {\"x\": 2}, \"c\": [{\"x\": 1}, {\"x\": 2}]}\n";
  EXPECT_EQ(ReadJsonFile(path)["b"]["x"], 2);
}

// A run-folder stamp nested 10^5 deep would overflow the stack of a later recursive copy.
TEST_F(JsonFileTest, DeepNestingIsAnError) {
  const std::string path = Path("deep.json");
  std::ofstream(path) << std::string(100000, '[') << std::string(100000, ']');
  ExpectError([&] { ReadJsonFile(path); }, {path, "nested deeper than 64"});
  std::ofstream(path) << std::string(60, '[') << std::string(60, ']');
  EXPECT_TRUE(ReadJsonFile(path).is_array());
}

}  // namespace
}  // namespace ibrdf

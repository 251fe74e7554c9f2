#include "workflow/build_id.h"

#include <elf.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.h"

namespace ibrdf {
namespace {

std::string Hex(const unsigned char* bytes, size_t count) {
  static const char kDigits[] = "0123456789abcdef";
  std::string text;
  for (size_t i = 0; i < count; ++i) {
    text += kDigits[bytes[i] >> 4];
    text += kDigits[bytes[i] & 15];
  }
  return text;
}

size_t AlignUp(size_t value, size_t alignment) { return (value + alignment - 1) / alignment * alignment; }

// The build id in one PT_NOTE segment's bytes, or "".
std::string BuildIdInNotes(const std::vector<unsigned char>& notes, size_t alignment) {
  size_t at = 0;
  while (at + sizeof(Elf64_Nhdr) <= notes.size()) {
    Elf64_Nhdr header;
    std::memcpy(&header, notes.data() + at, sizeof(header));
    const size_t name_at = at + sizeof(header);
    const size_t desc_at = name_at + AlignUp(header.n_namesz, alignment);
    const size_t next = desc_at + AlignUp(header.n_descsz, alignment);
    if (desc_at > notes.size() || next > notes.size() + alignment) break;
    if (header.n_type == NT_GNU_BUILD_ID && header.n_namesz == 4 &&
        std::memcmp(notes.data() + name_at, "GNU", 4) == 0 && desc_at + header.n_descsz <= notes.size() &&
        header.n_descsz > 0) {
      return Hex(notes.data() + desc_at, header.n_descsz);
    }
    at = next;
  }
  return "";
}

}  // namespace

std::string ElfBuildId(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "cannot open for reading");
  Elf64_Ehdr elf;
  if (!in.read(reinterpret_cast<char*>(&elf), sizeof(elf))) return "";
  if (std::memcmp(elf.e_ident, ELFMAG, SELFMAG) != 0 || elf.e_ident[EI_CLASS] != ELFCLASS64 ||
      elf.e_phentsize != sizeof(Elf64_Phdr)) {
    return "";
  }
  for (int i = 0; i < elf.e_phnum; ++i) {
    Elf64_Phdr segment;
    in.seekg(std::streamoff(elf.e_phoff + uint64_t(i) * sizeof(Elf64_Phdr)));
    if (!in.read(reinterpret_cast<char*>(&segment), sizeof(segment))) return "";
    if (segment.p_type != PT_NOTE || segment.p_filesz > (1u << 20)) continue;
    std::vector<unsigned char> notes(segment.p_filesz);
    in.seekg(std::streamoff(segment.p_offset));
    if (!in.read(reinterpret_cast<char*>(notes.data()), std::streamsize(notes.size()))) return "";
    const std::string id = BuildIdInNotes(notes, segment.p_align == 8 ? 8 : 4);
    if (!id.empty()) return "gnu-build-id:" + id;
  }
  return "";
}

std::string FileContentHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "cannot open for reading");
  uint64_t hash = 14695981039346656037ull;  // FNV-1a, 64 bits
  std::vector<char> buffer(1 << 16);
  while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      hash = (hash ^ static_cast<unsigned char>(buffer[size_t(i)])) * 1099511628211ull;
    }
  }
  unsigned char bytes[8];
  for (int i = 0; i < 8; ++i) bytes[i] = static_cast<unsigned char>(hash >> (56 - 8 * i));
  return "fnv1a64:" + Hex(bytes, 8);
}

namespace {

std::string BinaryId(const std::string& path) {
  const std::string elf = ElfBuildId(path);
  return elf.empty() ? FileContentHash(path) : elf;
}

// The front end that started this process (apps/main.cc sets IBRDF_TOOL before it execs a
// subcommand's binary), or "" when it was started directly.
std::string ToolFrontEnd() {
  const char* tool = std::getenv("IBRDF_TOOL");
  if (!tool || !std::filesystem::is_regular_file(tool)) return "";
  return tool;
}

}  // namespace

std::string ExecutableBuildId() {
  static const std::string id = [] {
    const std::string tool = ToolFrontEnd();
    if (tool.empty()) return BinaryId("/proc/self/exe");
    // The tool is the front end and every ibrdf-<name> binary beside it: one id over all of them.
    std::vector<std::string> binaries = {tool};
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(tool).parent_path())) {
      if (entry.path().filename().string().rfind("ibrdf-", 0) == 0 && entry.is_regular_file()) {
        binaries.push_back(entry.path().string());
      }
    }
    std::sort(binaries.begin() + 1, binaries.end());
    uint64_t hash = 14695981039346656037ull;  // FNV-1a over "name=id;" of each binary
    for (const std::string& binary : binaries) {
      for (char c : std::filesystem::path(binary).filename().string() + "=" + BinaryId(binary) + ";") {
        hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
      }
    }
    unsigned char bytes[8];
    for (int i = 0; i < 8; ++i) bytes[i] = static_cast<unsigned char>(hash >> (56 - 8 * i));
    return "ibrdf-tool:" + Hex(bytes, 8);
  }();
  return id;
}

std::string ExecutablePath() {
  const std::string tool = ToolFrontEnd();
  if (!tool.empty()) return tool;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  IBRDF_CHECK(!error) << "cannot read /proc/self/exe: " << error.message();
  return self.string();
}

}  // namespace ibrdf

// The output guard of every stage's command: a file or folder a command writes is never one of its
// inputs (nor a folder holding one, symlinks resolved), and an existing one is replaced only when the
// user said so. The commands call it before they read or write anything, so a refused command leaves
// nothing behind.
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

// Throws Error unless `output` (a file or a folder the command writes or replaces) may be written. It
// must not be one of the command's inputs, nor a folder that holds one, overwrite or not; an existing
// output is replaced only with `overwrite` (--overwrite); its parent folder must exist. `inputs`: every
// file the command reads (missing ones and "" are ignored), and every input folder.
void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs);

// A file a stage writes beside the output the user named (a sidecar <out>.json): `format` is the JSON
// "format" of the file the stage writes there, which marks an existing one as the stage's own.
struct CompanionFile {
  std::string path;
  std::string format;
};

// The output guard over every file a stage writes: RequireWritableOutput for `output` and for each
// companion; an existing companion is replaced only when it is the stage's own (its "format" is the
// companion's), --overwrite or not, since the user named only `output` (`--out mat` beside a material
// file mat.json, `--out s1/truth` beside a session's truth.json).
void RequireWritableOutputs(const std::string& output, const std::vector<CompanionFile>& companions, bool overwrite,
                            const std::vector<std::string>& inputs);

// The first half of RequireWritableOutput: `output` is no input and holds none (for `run`, whose folder
// is resumed rather than replaced).
void RequireOutputOutsideInputs(const std::string& output, const std::vector<std::string>& inputs);

// The inputs of a stage that reads a session (core/session.h): its files, its manifest and its folder.
// A template, so that a binary whose command reads no session does not link the session code.
template <typename SessionType>
std::vector<std::string> SessionInputs(const SessionType& session) {
  std::vector<std::string> inputs = session.InputFiles();
  inputs.push_back(session.manifest_path);
  inputs.push_back(session.directory);
  return inputs;
}

// Every regular file under `folder`, recursively (none if it is not a folder): the inputs of a command
// that reads a whole folder (a run folder, a COLMAP model, a calibration folder).
std::vector<std::string> FilesUnder(const std::string& folder);

}  // namespace ibrdf

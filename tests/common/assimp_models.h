// Debian's assimp-testmodels in formats other than glTF (COLLADA, Blender, ...), converted to glTF 2.0
// by assimp-utils' `assimp export` (tools/bootstrap.sh installs both): real models nobody here wrote.
#pragma once
#include <stdlib.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>
#include <vector>

namespace testfiles {

constexpr const char* kAssimpModels = "/usr/share/assimp/models";

// `source` (relative to kAssimpModels) converted once per test binary for each list `beside`, into a
// folder of its own with the files `beside` copied next to it (textures the model names by relative
// URI); the folders go when the binary exits. The path whether or not the conversion worked: loading
// a missing file fails the test that loads it.
inline std::string converted_model(const std::string& source, const std::vector<std::string>& beside = {}) {
  struct Folder {
    std::string dir, glb;
    Folder(const std::string& source, const std::vector<std::string>& beside) {
      const std::filesystem::path from = std::filesystem::path(kAssimpModels) / source;
      char tmpl[] = "/tmp/maskline-model-XXXXXX";
      if (!mkdtemp(tmpl)) return;
      dir = tmpl;
      glb = dir + "/" + from.stem().string() + ".glb";
      std::string cmd;
      for (const std::string& file : beside) cmd += "cp '" + (from.parent_path() / file).string() + "' " + dir + "/ && ";
      cmd += "assimp export '" + from.string() + "' " + glb + " -f glb2 >/dev/null 2>&1";
      if (std::system(cmd.c_str()) != 0) glb = dir + "/conversion-failed.glb";
    }
    Folder(const Folder&) = delete;
    ~Folder() {
      std::error_code ec;
      if (!dir.empty()) std::filesystem::remove_all(dir, ec);
    }
  };
  std::string key = source;  // the same source with other files beside is another folder
  for (const std::string& file : beside) key += '\n' + file;
  static std::map<std::string, Folder> folders;  // nodes never move
  const auto it = folders.try_emplace(key, source, beside).first;
  return it->second.glb.empty() ? "/tmp/maskline-model-not-made/" + source : it->second.glb;
}

}  // namespace testfiles

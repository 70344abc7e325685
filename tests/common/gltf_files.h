// The glTF inputs that tests walk: every .gltf and .glb below a folder (Debian's assimp-testmodels
// installs good, odd and broken ones under kAssimpGltf2Models).
#pragma once
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace testfiles {

constexpr const char* kAssimpGltf2Models = "/usr/share/assimp/models/glTF2";

// Every file below `dir` whose name ends in .gltf or .glb (any case), sorted; empty if `dir` is missing.
inline std::vector<std::string> gltf_files_under(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (std::filesystem::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb") out.push_back(it->path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace testfiles

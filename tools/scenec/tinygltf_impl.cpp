// The one translation unit that compiles Debian's header-only tinygltf (and the stb image code it
// needs). Image files are not loaded (TINYGLTF_NO_EXTERNAL_IMAGE) and embedded images are not decoded
// (gltf_import.cpp installs a loader that only keeps the reference): textures are references for now.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

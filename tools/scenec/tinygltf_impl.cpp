// The one translation unit that compiles Debian's header-only tinygltf (and the stb image code it
// needs). Images, embedded or external, are decoded by the loader gltf_import.cpp installs (stb_image,
// with size limits checked before decoding).
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

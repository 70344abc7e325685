// The bench driver's pieces shared between its files (tools/bench).
#pragma once
#include <string>

#include "scene/scene.h"
#include "view/view.h"

// The camera every bench measurement of a compiled scene uses (bench.cpp).
ml::Camera bench_camera(const std::string& path, const ml::Scene& scene, int w, int h);

// `bench quality SCENE.mls WxH`: antialiasing error of both renderers against the oracle (quality.cpp).
int quality(const std::string& path, const std::string& size);

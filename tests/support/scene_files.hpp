// A test fixture for scene files: a fresh temporary folder per test, writing scene (and mesh)
// files into it, loading them, and the "<file>: <key>: <problem>" message a bad one gives.
#pragma once

#include "sim/scene/scene.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace clothsim::testing {

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "clothsim_scene_files_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = dir_ / name;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path) << text;
    return path;
  }

  Scene load(const std::string& text, const std::string& name = "scene.json") const {
    return load_scene(write(name, text), nullptr);
  }

  // The SceneError message for `text`, or "no error".
  std::string error(const std::string& text, const std::string& name = "scene.json") const {
    try {
      load(text, name);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  }

  // The message expected for a problem at a key, with the file prefix.
  std::string expected(const std::string& key_and_problem) const {
    return (dir_ / "scene.json").string() + ": " + key_and_problem;
  }

  std::filesystem::path dir_;
};

}  // namespace clothsim::testing

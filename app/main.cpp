// Command-line entry point: `clothsim SCENE.json [--out DIR]`. Argument parsing (CLI11) lives in
// this file only; the work is done by run_scene_file (app/run.hpp).
#include "app/run.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

int main(int argc, char** argv) {
  CLI::App app{
      "clothsim: Kirchhoff-Love thin-shell cloth simulator on Loop-subdivision surfaces.\n"
      "Runs the analysis described by SCENE (a JSON file, see scenes/README.md) and writes\n"
      "result.json and limit.obj to DIR/<scene name>/.",
      "clothsim"};
  std::string scene;
  std::string out = "out";
  app.add_option("scene", scene, "Scene file (JSON)")->required()->type_name("SCENE.json");
  app.add_option("--out", out, "Output root; results go to DIR/<scene name>/")
      ->type_name("DIR")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "clothsim: error: " << e.what() << "\nRun with --help for usage.\n";
    return 1;
  }
  return clothsim::run_scene_file(scene, out);
}

// render_bench: time to render one 1280 x 720 frame with 4x MSAA of a smooth ~50k-triangle
// mesh (a finely tessellated wavy cylinder generated here) over a ground plane, with and without
// a wireframe overlay, and with the mesh's shadow on the ground (BM_render_1280x720_msaa4: Renderer::render, i.e. everything from the Frame to the RGB
// image in memory, no PNG). BM_render_phases splits the same work into its phases
// (RenderPhases, with glFinish between them; counters in ms per frame), BM_write_png times the
// PNG encoding and writing of the rendered frame (write_png into a temporary folder), which a
// run adds per frame. `render_bench --png=PATH` also writes the rendered frame for inspection.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "render/png_io.hpp"
#include "render/renderer.hpp"

#include <unistd.h>

namespace {

using namespace clothsim::render;

constexpr int kAround = 160;  // vertices around the cylinder
constexpr int kAlong = 158;   // rings along it: 2 · 160 · 157 = 50 240 triangles
constexpr int kWidth = 1280;
constexpr int kHeight = 720;

// A vertical open cylinder whose radius ripples around and along it. Normals are left empty,
// so the renderer computes smooth vertex normals (part of the timed work).
Mesh wavy_cylinder() {
  Mesh mesh;
  const double pi = std::numbers::pi;
  for (int j = 0; j < kAlong; ++j) {
    const double v = static_cast<double>(j) / (kAlong - 1);
    const double y = 0.2 + 1.6 * v;
    for (int i = 0; i < kAround; ++i) {
      const double u = 2 * pi * i / kAround;
      const double r =
          0.5 + 0.06 * std::sin(7 * u + 3 * v) * std::cos(5 * pi * v) + 0.08 * std::sin(2 * pi * v);
      mesh.positions.push_back(static_cast<float>(r * std::cos(u)));
      mesh.positions.push_back(static_cast<float>(y));
      mesh.positions.push_back(static_cast<float>(-r * std::sin(u)));
    }
  }
  for (int j = 0; j + 1 < kAlong; ++j) {
    for (int i = 0; i < kAround; ++i) {
      const auto a = static_cast<unsigned>(j * kAround + i);
      const auto b = static_cast<unsigned>(j * kAround + (i + 1) % kAround);
      const auto c = a + kAround;
      const auto d = b + kAround;
      mesh.triangles.insert(mesh.triangles.end(), {a, b, d, a, d, c});
    }
  }
  mesh.color = {0.75f, 0.12f, 0.1f};
  mesh.back_color = {0.35f, 0.3f, 0.6f};
  return mesh;
}

Lines ring_lines(const Mesh& mesh, int every) {
  Lines lines;
  lines.positions = mesh.positions;
  for (int j = 0; j < kAlong; j += every) {
    for (int i = 0; i < kAround; ++i) {
      lines.segments.push_back(static_cast<unsigned>(j * kAround + i));
      lines.segments.push_back(static_cast<unsigned>(j * kAround + (i + 1) % kAround));
    }
  }
  lines.color = {0.1f, 0.05f, 0.05f};
  return lines;
}

Frame bench_frame(bool wireframe, bool shadow = false) {
  Frame frame;
  frame.meshes.push_back(wavy_cylinder());
  if (wireframe) frame.lines.push_back(ring_lines(frame.meshes[0], 8));
  frame.ground = true;
  frame.ground_height = 0;
  frame.shadow = shadow;
  frame.width = kWidth;
  frame.height = kHeight;
  frame.camera = frame_bounds({-0.65f, 0, -0.65f}, {0.65f, 1.8f, 0.65f}, 35, {-0.5f, -0.45f, -1},
                              {0, 1, 0}, static_cast<float>(kWidth) / kHeight);
  return frame;
}

Renderer& renderer() {
  static Renderer instance(kWidth, kHeight, 4);
  return instance;
}

void BM_render_1280x720_msaa4(benchmark::State& state) {
  const Frame frame = bench_frame(state.range(0) != 0, state.range(1) != 0);
  benchmark::DoNotOptimize(renderer().render(frame));  // warm-up: framebuffers, JIT
  for (auto _ : state) {
    Image image = renderer().render(frame);
    benchmark::DoNotOptimize(image.rgb.data());
  }
  state.counters["triangles"] = static_cast<double>(frame.meshes[0].triangles.size() / 3);
  state.counters["samples"] = renderer().info().samples;
}
BENCHMARK(BM_render_1280x720_msaa4)
    ->ArgNames({"wireframe", "shadow"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->Repetitions(7)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();

// The phases of render() (RenderPhases), with glFinish between them: counters in ms per frame
// (the iteration time is their sum plus the timing's own overhead).
void BM_render_phases(benchmark::State& state) {
  const Frame frame = bench_frame(state.range(0) != 0, state.range(1) != 0);
  benchmark::DoNotOptimize(renderer().render(frame));
  renderer().set_phase_timing(true);
  RenderPhases sum;
  for (auto _ : state) {
    Image image = renderer().render(frame);
    benchmark::DoNotOptimize(image.rgb.data());
    const RenderPhases& p = renderer().last_phases();
    sum.prepare += p.prepare;
    sum.shadow += p.shadow;
    sum.backdrop += p.backdrop;
    sum.restore += p.restore;
    sum.upload += p.upload;
    sum.draw += p.draw;
    sum.raster += p.raster;
    sum.resolve += p.resolve;
    sum.read += p.read;
    sum.convert += p.convert;
  }
  renderer().set_phase_timing(false);
  const double n = static_cast<double>(state.iterations());
  state.counters["prepare_ms"] = sum.prepare / n;
  state.counters["shadow_ms"] = sum.shadow / n;
  state.counters["backdrop_ms"] = sum.backdrop / n;
  state.counters["restore_ms"] = sum.restore / n;
  state.counters["upload_ms"] = sum.upload / n;
  state.counters["draw_ms"] = sum.draw / n;
  state.counters["raster_ms"] = sum.raster / n;
  state.counters["resolve_ms"] = sum.resolve / n;
  state.counters["read_ms"] = sum.read / n;
  state.counters["convert_ms"] = sum.convert / n;
}
BENCHMARK(BM_render_phases)
    ->ArgNames({"wireframe", "shadow"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->Repetitions(7)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();

// write_png of the rendered frame (no wireframe): encoding, writing a temporary file, renaming.
void BM_write_png(benchmark::State& state) {
  const Image image = renderer().render(bench_frame(false));
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("render_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "frame.png").string();
  for (auto _ : state) write_png(path, image);
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_write_png)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->Repetitions(7)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int k = 0; k < argc; ++k) {
    if (std::strncmp(argv[k], "--png=", 6) == 0) {
      const std::string path = argv[k] + 6;
      write_png(path, renderer().render(bench_frame(true, true)));
      std::cout << "wrote " << path << "\n";
    } else {
      rest.push_back(argv[k]);
    }
  }
  int rest_count = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_count, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rest_count, rest.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

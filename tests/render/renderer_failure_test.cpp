// Renderer failures must end in clear exceptions, never in a crash, and every renderer must stay
// destructible. A run that ran OSMesa out of memory once crashed (SIGSEGV) in the destructor's
// OSMesaMakeCurrent. Out of memory is produced here for real, in a child process (a gtest death
// test) whose address space is capped just above what it uses (RLIMIT_AS): the child renders
// under the cap, destroys its renderers and must then exit with code 0.
#include "render/renderer.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>

namespace clothsim::render {
namespace {

Frame triangle_frame(int width, int height) {
  Frame frame;
  Mesh mesh;
  mesh.positions = {-1.0f, -0.8f, 0.0f, 1.0f, -0.8f, 0.0f, 0.0f, 1.0f, 0.0f};
  mesh.triangles = {0, 1, 2};
  frame.meshes.push_back(mesh);
  frame.camera.eye = {0, 0, 3};
  frame.camera.target = {0, 0, 0};
  frame.width = width;
  frame.height = height;
  return frame;
}

// The process's virtual memory size [bytes] (VmSize of /proc/self/status).
long long address_space_in_use() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmSize:", 0) == 0) return std::stoll(line.substr(7)) * 1024;
  }
  return -1;
}

// Caps the address space at what is in use plus `margin` bytes; lift_cap() undoes it.
void cap_address_space(long long margin) {
  const rlimit cap{static_cast<rlim_t>(address_space_in_use() + margin), RLIM_INFINITY};
  if (setrlimit(RLIMIT_AS, &cap) != 0) {
    std::fprintf(stderr, "setrlimit failed\n");
    std::exit(2);
  }
}

void lift_cap() {
  const rlimit none{RLIM_INFINITY, RLIM_INFINITY};
  setrlimit(RLIMIT_AS, &none);
}

// Runs `body` in the child; a failed expectation prints its reason and exits with code 1.
[[noreturn]] void child(const std::function<void()>& body) {
  try {
    body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "unexpected exception: %s\n", e.what());
    std::exit(1);
  }
  std::fprintf(stderr, "child done\n");
  std::exit(0);
}

void expect(bool condition, const std::string& what) {
  if (condition) return;
  std::fprintf(stderr, "failed: %s\n", what.c_str());
  std::exit(1);
}

// RLIMIT_AS cannot be used under the address, thread or memory sanitizers (their shadow memory
// reserves terabytes of address space).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kAddressSpaceCapWorks = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
constexpr bool kAddressSpaceCapWorks = false;
#else
constexpr bool kAddressSpaceCapWorks = true;
#endif
#else
constexpr bool kAddressSpaceCapWorks = true;
#endif

TEST(RendererFailure, SizeBeyondTheGlLimitIsAClearErrorAndLeavesRenderingUsable) {
  try {
    Renderer too_large(1 << 20, 16);
    FAIL() << "a 1048576-pixel-wide renderer was created";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds the GL limit"), std::string::npos) << e.what();
  }
  // The failed construction released its context: new renderers work, and come and go.
  for (int i = 0; i < 3; ++i) {
    Renderer renderer(64, 48);
    const Image image = renderer.render(triangle_frame(64, 48));
    EXPECT_EQ(image.width, 64);
  }
}

TEST(RendererFailure, OutOfMemoryBeforeDrawingLeavesTheRendererUsable) {
  if (!kAddressSpaceCapWorks) GTEST_SKIP() << "address-space caps do not work under this sanitizer";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(child([] {
                Renderer renderer(256, 256);
                renderer.render(triangle_frame(256, 256));
                // A mesh of 4 million vertices whose vertex data (96 MB) cannot be allocated.
                Frame frame = triangle_frame(256, 256);
                Mesh& mesh = frame.meshes[0];
                const unsigned vertices = 4'000'000;
                mesh.positions.assign(3 * static_cast<std::size_t>(vertices), 0.0f);
                for (unsigned v = 0; v < vertices; ++v) mesh.positions[3 * v] = static_cast<float>(v % 7) / 7;
                mesh.triangles.resize(vertices - vertices % 3);
                for (unsigned i = 0; i < mesh.triangles.size(); ++i) mesh.triangles[i] = i;
                cap_address_space(32ll << 20);
                bool threw = false;
                try {
                  renderer.render(frame);
                } catch (const std::bad_alloc&) {
                  threw = true;
                }
                lift_cap();
                expect(threw, "rendering under the cap threw std::bad_alloc");
                // No GL call was made for that frame: the same renderer goes on.
                const Image image = renderer.render(triangle_frame(256, 256));
                expect(image.width == 256, "the renderer renders again");
              }),
              ::testing::ExitedWithCode(0), "child done");
}

TEST(RendererFailure, FramebufferOutOfMemoryIsAClearErrorAndTeardownIsSafe) {
  if (!kAddressSpaceCapWorks) GTEST_SKIP() << "address-space caps do not work under this sanitizer";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(child([] {
                {
                  Renderer renderer(4096, 4096);
                  renderer.render(triangle_frame(64, 48));
                  // A 4096² frame: 112 MB of image and read-back buffer (allocated first, and
                  // allowed for), then at least 2 × 64 MB of framebuffers in GL, which are not.
                  cap_address_space(180ll << 20);
                  std::string first;
                  try {
                    renderer.render(triangle_frame(4096, 4096));
                  } catch (const std::runtime_error& e) {
                    first = e.what();
                  }
                  lift_cap();
                  std::fprintf(stderr, "first failure: %s\n", first.c_str());
                  expect(first.find("framebuffer") != std::string::npos || first.find("GL_OUT_OF_MEMORY") != std::string::npos,
                         "the failure names the framebuffer or GL_OUT_OF_MEMORY");
                  // The failed context is not used again, with a clear error.
                  std::string second;
                  try {
                    renderer.render(triangle_frame(64, 48));
                  } catch (const std::runtime_error& e) {
                    second = e.what();
                  }
                  expect(second.find("unusable after an earlier failure") != std::string::npos,
                         "a later render() is refused: '" + second + "'");
                }  // destroyed here: must not crash
                // A new renderer works after the failed one.
                Renderer fresh(64, 48);
                expect(fresh.render(triangle_frame(64, 48)).width == 64, "a new renderer renders");
              }),
              ::testing::ExitedWithCode(0), "child done");
}

}  // namespace
}  // namespace clothsim::render

// Which supernodal solve kernels this build and this processor can run (sim/solver/
// supernodal_kernels.hpp). The AVX2 + FMA + F16C kernels are compiled only where the compiler
// targets x86-64 (CLOTHSIM_X86_KERNELS, set in sim/solver/CMakeLists.txt); elsewhere supported()
// is false and the portable Eigen path runs.
#include "sim/solver/supernodal_kernels.hpp"

#include "sim/core/kernel_choice.hpp"

#include <cstdlib>

#if defined(CLOTHSIM_X86_KERNELS)
#include <cpuid.h>
#endif

namespace clothsim::supernodal_avx2 {

#if defined(CLOTHSIM_X86_KERNELS)
bool supported() {
  __builtin_cpu_init();
  // F16C through CPUID leaf 1 (ECX bit 29): clang 14's __builtin_cpu_supports does not know "f16c".
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) != 0 && (ecx & bit_F16C) != 0;
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && f16c && vector_kernels_allowed();
}
#else
bool supported() { return false; }
// Never called (supported() is false); defined so that the dispatching code links.
void forward(const float*, int, int, float*, float*) { std::abort(); }
void backward(const float*, int, int, float*, const float*) { std::abort(); }
void forward(const unsigned short*, int, int, const float*, float*, float*) { std::abort(); }
void backward(const unsigned short*, int, int, const float*, float*, const float*) { std::abort(); }
void to_half(const float*, const float*, const int*, int, int, unsigned short*) { std::abort(); }
#endif

}  // namespace clothsim::supernodal_avx2

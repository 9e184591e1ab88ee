// Exit status 0 where this CPU runs the x86-64-v4 core (AVX-512 F, DQ, BW, VL): CMake's
// try_run decides with it whether to build the 16-lane path tests (tests/cpp/CMakeLists.txt).
int main() {
  __builtin_cpu_init();
  const bool v4 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
  return v4 ? 0 : 1;
}

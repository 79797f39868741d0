// libFuzzer entry point for one reader, selected by VITRI_FUZZ_<reader> (see fuzz/CMakeLists.txt).
// Contract under test: any input either parses or throws vitri::Error; never a crash, a hang, an
// out-of-bounds access or an allocation the input cannot justify.
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
#if defined(VITRI_FUZZ_off)
    (void)vitri::parse_off(text, "fuzz.off");
#elif defined(VITRI_FUZZ_obj)
    (void)vitri::parse_obj(text, "fuzz.obj");
#elif defined(VITRI_FUZZ_ply)
    (void)vitri::parse_ply(text, "fuzz.ply");
#elif defined(VITRI_FUZZ_xyzv)
    (void)vitri::parse_xyzv(text, "fuzz.xyzv");
#elif defined(VITRI_FUZZ_points)
    (void)vitri::parse_points(text, "fuzz.xyz");
#elif defined(VITRI_FUZZ_pcd)
    (void)vitri::parse_input(text, "fuzz.pcd");
#elif defined(VITRI_FUZZ_las)
    (void)vitri::parse_input(text, "fuzz.las");
#elif defined(VITRI_FUZZ_stl)
    (void)vitri::parse_stl(text, "fuzz.stl");
#endif
  } catch (const vitri::Error&) {
  }
  return 0;
}

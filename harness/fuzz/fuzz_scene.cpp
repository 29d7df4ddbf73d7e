// libFuzzer target for the scene reader (sweep, stress and smoothing scenes).
// The contract under test: any byte string either parses or throws
// SceneError (a message naming file, field and expectation). Any other
// exception, a crash, a sanitizer report or a hang is a bug.
// Built and run by scripts/fuzz_scene.sh.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "idcol_harness/scene.hpp"

using namespace idcol::harness;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Scene s = parse_scene(text, "fuzz.toml");
    // A sweep scene that parses must print back to a scene that parses.
    if (s.kind() == SceneKind::Sweep) (void)parse_scene(scene_to_toml(s), "roundtrip.toml");
  } catch (const SceneError&) {
  }
  return 0;
}

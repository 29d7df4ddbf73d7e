// libFuzzer target for the scene reader (every kind of scene).
// The contract under test: any byte string either parses or throws
// SceneError (a message naming file, field and expectation). Any other
// exception, a crash, a sanitizer report or a hang is a bug.
// Built by -DIDCOL_BUILD_FUZZERS=ON (harness/fuzz/CMakeLists.txt); run by
// scripts/fuzz_scene.sh and, in CI, by scripts/ci_fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "studies/study.hpp"
#include "scene/scene.hpp"

using namespace idcol::harness;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Scene s = parse_scene(text, "fuzz.toml");
    // A scene that parses and prints as read (a sweep's) must print back to
    // a scene that parses.
    const StudyKind& kind = *study_kind_named(s.kind);
    if (kind.prints_scene()) (void)parse_scene(kind.scene_text(s), "roundtrip.toml");
  } catch (const SceneError&) {
  }
  return 0;
}

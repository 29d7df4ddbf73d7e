// toml++'s implementation, compiled once into the harness for the fuzz and
// sanitizer builds (-DIDCOL_BUILD_FUZZERS=ON), so that the TOML parser is
// instrumented like the harness's own code; other builds link Debian's
// libtomlplusplus instead (harness/CMakeLists.txt).
#define TOML_IMPLEMENTATION
#include <toml++/toml.h>

// `idcol_harness history add|show` (report/history.hpp): its usage text and
// its command, kept out of main.cpp.
#pragma once

#include <string>
#include <vector>

namespace idcol::harness {

extern const char* const kHistoryUsage;

/// a = {"history", "add"|"show", ...}. Returns the exit status: 0, or 2 on
/// bad input (the message on stderr).
int cmd_history(const std::vector<std::string>& a);

}  // namespace idcol::harness

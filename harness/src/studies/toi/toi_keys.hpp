// The keys only a time-of-impact study's results file has (io/keys.hpp
// explains why keys are constants).
#pragma once

#include "io/keys.hpp"

namespace idcol::harness::key {

inline constexpr char toi_pairs[] = "pairs";  // the results file's array of entries (a pair under one motion model)
inline constexpr char motions[] = "motions";  // motions of the entry
inline constexpr char oracle_verdicts[] = "oracle";       // what the independent oracle says of the motions ...
inline constexpr char clear_hits[] = "clear_hits";        // ... the bodies certainly meet
inline constexpr char clear_misses[] = "clear_misses";    // ... they certainly do not
inline constexpr char grazes[] = "grazes";                // ... too close to call: left out of the verdicts
inline constexpr char idcol_toi[] = "idcol";              // idcol::time_of_impact's tally
inline constexpr char fcl_methods[] = "fcl";              // FCL continuousCollide's tallies, by method
inline constexpr char impacts[] = "impacts";              // answers: a contact at t in (0, 1]
inline constexpr char no_impacts[] = "no_impacts";        // answers: no contact
inline constexpr char initially_in_contact[] = "initially_in_contact";
inline constexpr char missed_contacts[] = "missed_contacts";  // oracle: a clear hit; method: no contact
inline constexpr char false_impacts[] = "false_impacts";      // oracle: a clear miss; method: a contact
inline constexpr char t_error[] = "t_error";                  // |t - t_oracle| over the clear hits found (outside the oracle's [t_lo, t_hi])
inline constexpr char solves_per_query[] = "solves_per_query";  // idcol: solves; FCL naive: collide calls
inline constexpr char us_per_query[] = "us_per_query";          // thread CPU time per query, the fastest of 3 loops over the entry's motions

}  // namespace idcol::harness::key

// The keys only a sweep's results file has (io/keys.hpp explains why keys
// are constants): the baselines' agreement with iDCOL and the derivatives'
// worst error.
#pragma once

#include "io/keys.hpp"

namespace idcol::harness::key {

// The baselines' agreement pass (studies/sweep/agreement.hpp).
inline constexpr char genuine_total[] = "genuine_total";                  // genuine disagreements, every method
inline constexpr char idcol_outside_bracket[] = "idcol_outside_bracket";  // iDCOL's alpha* outside the oracle's bracket
inline constexpr char band[] = "band";                                    // a disagreement the oracle's bracket explains
inline constexpr char failed[] = "failed";                                // the method gave no answer
inline constexpr char alpha_abs_err[] = "alpha_abs_err";
inline constexpr char alpha_rel_err[] = "alpha_rel_err";
inline constexpr char normal_angle_rad[] = "normal_angle_rad";
// Per method, what it answers besides its boolean (MethodAnswerStats).
inline constexpr char answers[] = "answers";
inline constexpr char normal_poses[] = "normal_poses";  // poses whose normals were compared
inline constexpr char alpha_poses[] = "alpha_poses";    // poses whose alpha* was compared with the oracle
inline constexpr char alpha_outside_bound[] = "alpha_outside_bound";    // alpha* off the oracle beyond the method's own bound
inline constexpr char alpha_rel_diff_idcol[] = "alpha_rel_diff_idcol";  // |alpha - iDCOL's alpha*| / iDCOL's
inline constexpr char method_iterations[] = "method_iterations";          // the method's own iteration count

// The derivatives against finite differences: the largest disagreement not
// reported unreliable.
inline constexpr char worst_error[] = "worst_error";

}  // namespace idcol::harness::key

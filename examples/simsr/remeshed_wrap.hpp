#pragma once
// The remeshed outer wrap, compiled in remeshed_wrap.cpp (built only with CGAL: SIMSR_HAVE_CGAL).
#include <simsr/scenario/softdeca/ict_template.hpp>

namespace simsr::cli {

/// scenario::remeshed_outer_wrap, instantiated here for exec::omp only.
scenario::IctOuterWrap remeshed_outer_wrap(exec::omp_t policy, const scenario::IctKit& kit, double edge_length);

}  // namespace simsr::cli

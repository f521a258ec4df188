// The tool's one unit with CGAL: the SoftDECA template's remeshed outer wrap for
// `simsr datagen --scenario softdeca --skin-edge CM`. Its own unit, outside the tool's unity unit,
// so that CGAL's -frounding-math reaches only this code, not the network and the solvers.
#include "remeshed_wrap.hpp"

#include <simsr/scenario/softdeca/remeshed_wrap.hpp>

namespace simsr::cli {

scenario::IctOuterWrap remeshed_outer_wrap(exec::omp_t policy, const scenario::IctKit& kit, double edge_length) {
  return scenario::remeshed_outer_wrap(policy, kit, edge_length);
}

}  // namespace simsr::cli

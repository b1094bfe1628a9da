#pragma once
// Contact summary of a periodic orbit: how the periodic sequence of states u_0 .. u_{K-1}
// (one stroboscopic map, periodic) sits against the switching surface H = 0.
//
// contact_summary inspects only the grid nodes: a contact that starts and ends between two nodes
// (shorter than a step, possible at coarse N near grazing) is not seen there; orbit_contacts
// (orbit_search.hpp) adds those from the interpolant. Models without switching: zero.
#include <algorithm>
#include <cmath>
#include <vector>

#include "delayspec/model.hpp"

namespace delayspec {

struct ContactSummary {
  int contacts = 0;           // maximal runs of consecutive nodes in region 1 (H > 0), cyclically,
                              // and (orbit_contacts) the contacts inside a step between two nodes
  long nodes_in_contact = 0;  // nodes with H > 0
  double max_H = -INFINITY;   // max of H over the nodes (orbit_contacts: over the interpolant)
  long steps_with_inner_contact = 0;  // (orbit_contacts) steps whose contact lies between their nodes
};

template <class Model>
ContactSummary contact_summary(const Model& model, const std::vector<Vec<Model::d>>& states) {
  ContactSummary s;
  if constexpr (!Model::has_switching) {
    s.max_H = NAN;
    return s;
  } else {
    const size_t K = states.size();
    for (size_t l = 0; l < K; ++l) {
      const double H = model.H(states[l]);
      s.max_H = std::max(s.max_H, H);
      if (H > 0) {
        ++s.nodes_in_contact;
        if (!(model.H(states[(l + K - 1) % K]) > 0)) ++s.contacts;  // a run starts here
      }
    }
    if (s.nodes_in_contact == static_cast<long>(K) && K > 0) s.contacts = 1;  // always in contact
    return s;
  }
}

}  // namespace delayspec

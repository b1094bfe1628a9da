// The orbit's contacts (orbit_search.hpp: orbit_contacts) count a contact that starts and ends
// inside a step, between two nodes outside the wall (issue 32, item 4): the impact orbit at
// e = 1.261, N = 200 (orbit = newton) touches the wall inside one step and at no node. Checked
// against the step's own event location, which shares no code with the Hermite interpolant the
// count uses: the steps of the orbit that locate an event with both nodes outside are the steps
// counted, and the interpolated max H is positive exactly then.
#include <gtest/gtest.h>

#include <vector>

#include "delayspec/builtin_analyses.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {
namespace {

TEST(OrbitContacts, AContactInsideAStepIsCountedAsTheStepLocatesIt) {
  ImpactParameters p;
  p.e = 1.261;
  const ImpactModel model(p);
  const auto analyses = builtin_analyses(model);
  MapSettings settings;
  settings.N = 200;
  settings.step.grid = GridLayout::uniform;  // the contact inside a step (aligned: its ends are nodes)
  OrbitSettings orbit;
  orbit.method = OrbitMethod::newton;
  OrbitRequest request;
  request.sequence = true;
  const LinearisedOrbit at = analyses->linearised_orbit(settings, orbit, request);
  EXPECT_EQ(at.contacts.nodes_in_contact, 0);
  EXPECT_GT(at.contacts.max_H, 0);
  EXPECT_EQ(at.contacts.contacts, at.contacts.steps_with_inner_contact);

  // The steps of the orbit, each taken again by the stepper from the orbit's states, with events.
  const StroboscopicMap<ImpactModel> map(TrapezoidStepper<ImpactModel>(model), make_grid(model.tau(), model.period(), 200));
  const HistoryGrid& g = map.grid();
  const long K = g.K, M = g.M;
  const auto u = [&](long l) { return Vec<2>(at.sequence.segment<2>(2 * (((l % K) + K) % K))); };
  long located = 0;
  for (long l = 0; l < K; ++l) {
    const auto [w0, w1, t, h] = g.delay_taps<2, Vec<2>>(l, [&](long i) { return u(i - M); });
    StepMap<2, 2> scratch;
    StepEvents events;
    map.stepper().step(t, g.h, u(l), w0, w1, scratch, &events);
    if (events.count > 0 && !(model.H(u(l)) > 0) && !(model.H(u(l + 1)) > 0)) ++located;
  }
  EXPECT_GE(located, 1);
  EXPECT_EQ(at.contacts.steps_with_inner_contact, located);
}

}  // namespace
}  // namespace delayspec

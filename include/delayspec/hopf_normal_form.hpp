#pragma once
// The first Lyapunov coefficient of a Hopf point of an equilibrium (issue 60, item 2): whether
// the orbit born there is stable (supercritical, l1 < 0: a soft loss of stability) or unstable
// (subcritical, l1 > 0: the state jumps away once the equilibrium loses stability; in machining,
// chatter below the linear lobes).
//
// For y' = f(X), X = (y(t), y(t - tau_1), ..., y(t - tau_n)) stacked, at the equilibrium y* with
// Delta(lambda) = lambda I - A - sum_i B_i exp(-lambda tau_i) and a simple root lambda = i omega
// (Kuznetsov, Elements of Applied Bifurcation Theory, 3rd ed., sec. 3.5, in the DDE form of
// DDE-BIFTOOL's normal-form module):
//
//   Delta(i omega) v = 0, |v|_2 = 1;   u^H Delta(i omega) = 0, u^H Delta'(i omega) v = 1;
//   Phi = (v, v e^{-i omega tau_1}, ...)         the critical mode phi(theta) = v e^{i omega theta} sampled;
//   h20 = Delta(2 i omega)^{-1} B(Phi, Phi),     H20 = (h20, h20 e^{-2 i omega tau_1}, ...);
//   h11 = Delta(0)^{-1} B(Phi, conj Phi),        H11 = (h11, h11, ...);
//   c1 = 1/2 u^H [C(Phi, Phi, conj Phi) + B(H20, conj Phi) + 2 B(H11, Phi)],   l1 = Re c1 / omega,
//
// B and C the second and third derivatives of f in X. Near the Hopf point the orbit is
// y* + 2 Re(z v e^{i omega t}) with |z|^2 = -Re(lambda'(p)) (p - p*) / Re c1 (checked in
// scripts/hopf_normal_form_reference.py against Wright's equation's closed form). l1's size
// depends on the normalisation of v (here |v|_2 = 1); its sign does not.
//
// B and C come from the model's exact Jacobian J(X) = [A B_1 .. B_n] (d x d(n+1)): B(U, V) =
// DJ(X)[U] V and C(U, U, V) = D^2 J(X)[U, U] V, each by fourth-order central differences along
// real directions (a complex U = a + i b by linearity, and D^2 J[a, b] by polarisation), at the
// step h = s (1 + |X|_inf) / |U|_inf. The step a model needs is not known in advance (truncation
// h^4 against rounding eps / h^2; Mackey-Glass's x^10 / (1 + x^10) wants h ~ 1e-3, where l1 is
// still 1e-8 off), so c1 is computed at s = 0.1 / 2^k, k = 0 .. 11, and extrapolated in s as
// Ridders does: T(k, j) removes the s^{2j+2} term of the even expansion the central stencils have
// (j <= 3). Each entry's error is taken as the largest of its distances to the two entries it
// came from and to its column's entry one step coarser, plus the rounding of J at its step: c1
// recomputed through a J whose entries are disturbed by 4 eps (two samples; rounding is amplified
// by 1 / h^2 and may hide where differences agree by chance). The entry with the least error
// gives c1 and a derivative bar of twice that. A polynomial f of degree <= 4 in X has no
// truncation; its bar is the rounding. The root's error adds |dl1/domega| (|Re lambda| + its
// error_bound) (at the located point the root is off the axis by what the parameter's bracket
// leaves); the bar is never below 16 eps times the size of c1's terms (they may cancel).
#include <complex>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "delayspec/equilibrium.hpp"

namespace delayspec {

// J = [A B_1 .. B_n] (d x d(n + 1)) at the history whose current state is y and whose delayed
// states are `delayed` (d n values, delay by delay as model.hpp stacks them).
using JacobianAt = std::function<Eigen::MatrixXd(const Eigen::VectorXd& y, const Eigen::VectorXd& delayed)>;

enum class HopfCriticality {
  supercritical,  // l1 + bar < 0: a stable orbit is born
  subcritical,    // l1 - bar > 0: an unstable orbit collapses onto the equilibrium
  degenerate      // |l1| <= bar (a generalised Hopf point within the bar), or no l1 (note says why)
};
// "supercritical", "subcritical", "degenerate".
std::string to_string(HopfCriticality criticality);

struct HopfNormalForm {
  double l1 = 0;        // Re c1 / omega, with |v|_2 = 1
  double l1_bound = 0;  // a bound on |l1 - exact|: the derivatives' and the root's parts (header comment)
  HopfCriticality criticality = HopfCriticality::degenerate;
  std::complex<double> c1;
  Eigen::VectorXcd eigenvector;  // v: Delta(i omega) v = 0, |v|_2 = 1, its largest entry real > 0
  double difference_step = 0;    // s of the chosen stencils
  std::string note;              // when no l1: why (l1 and l1_bound then NaN and infinity)
};

// The normal form at the Hopf point: the equilibrium y with `at_equilibrium` (its A, B, delays),
// `root` its critical root (Im > 0), `jacobian` the model's J there and nearby. No throw for a
// degenerate point (Delta(0) or Delta(2 i omega) singular: a zero-Hopf point or a 1:2 resonance
// of roots), which gets criticality = degenerate and a note.
HopfNormalForm hopf_normal_form(const JacobianAt& jacobian, const ConstantHistory& at_equilibrium,
                                const Eigen::VectorXd& y, const CharacteristicRoot& root);

}  // namespace delayspec

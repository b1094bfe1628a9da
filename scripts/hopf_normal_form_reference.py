#!/usr/bin/env python3
"""The first Lyapunov coefficient of a DDE's Hopf point, computed independently of delayspec.

For y' = f(y(t), y(t - tau_1), ..., y(t - tau_n); p) this script locates the Hopf point itself
(the equilibrium, p and omega from det Delta(i omega) = 0 by mpmath.findroot at 40 digits) and
evaluates the normal-form coefficient with the second and third derivatives of f taken by
mpmath.diff at 40 digits (f is analytic, so complex directions are differentiated directly):

  Delta(l) = l I - A - sum_i B_i exp(-l tau_i),  Delta(i w) v = 0 (|v| = 1),
  u^H Delta(i w) = 0 with u^H Delta'(i w) v = 1,
  Phi = (v, v e^{-i w tau_1}, ...),  h20 = Delta(2 i w)^{-1} B(Phi, Phi),  h11 = Delta(0)^{-1} B(Phi, conj Phi),
  c1 = 1/2 u^H [C(Phi, Phi, conj Phi) + B(H20, conj Phi) + 2 B(H11, Phi)],  H20_i = h20 e^{-2 i w tau_i},
  l1 = Re c1 / w   (Kuznetsov, Elements of Applied Bifurcation Theory, 3rd ed., sec. 3.5; the DDE
  form as in DDE-BIFTOOL's normal-form module).

It also checks the convention on Wright's equation y' = -a y(t - 1) (1 + y), whose orbit born at
a = pi/2 is known in closed form (Chow and Mallet-Paret 1977): y = sqrt(40 (a - pi/2) / (3 pi - 2))
cos(pi t / 2) + O(a - pi/2). The normal form's orbit has amplitude 2 |z| |v_1|,
|z|^2 = -Re(lambda'(a)) (a - pi/2) / Re c1: the two agree to 40 digits or the script fails.

Usage: /usr/bin/python3 scripts/hopf_normal_form_reference.py  (prints each model's p, omega, l1)
"""
import mpmath as mp

mp.mp.dps = 40


def jac_blocks(f, y, taus, p):
    """A and the B_i of f at the constant history y (d x d each), by mpmath.diff."""
    d, n = len(y), len(taus)

    def partial(row, block, col):
        def g(s):
            ys = [list(y) for _ in range(n + 1)]
            ys[block][col] += s
            return f(ys[0], ys[1:], p)[row]
        return mp.diff(g, 0)

    return [mp.matrix([[partial(r, b, c) for c in range(d)] for r in range(d)]) for b in range(n + 1)]


def delta(blocks, taus, lam, derivative=False):
    d = blocks[0].rows
    if derivative:
        m = mp.eye(d)
        for B, tau in zip(blocks[1:], taus):
            m += tau * B * mp.exp(-lam * tau)
        return m
    m = lam * mp.eye(d) - blocks[0]
    for B, tau in zip(blocks[1:], taus):
        m -= B * mp.exp(-lam * tau)
    return m


def multilinear(f, y, taus, p, dirs, orders):
    """d^k/ds1^o1 ... f(Y + s1 U1 + ...) at 0: B (orders (1,1)) and C ((2,1)); U are stacked."""
    d, n = len(y), len(taus)

    def g(*s):
        pts = []
        for b in range(n + 1):
            pts.append([y[c] + sum(si * U[b * d + c] for si, U in zip(s, dirs)) for c in range(d)])
        return pts

    return mp.matrix([mp.diff(lambda *s: f(g(*s)[0], g(*s)[1:], p)[r], [0] * len(dirs), orders)
                      for r in range(d)])


def equilibrium(f, y0, taus, p):
    d, n = len(y0), len(taus)
    if d == 1:
        return [mp.findroot(lambda y: f([y], [[y]] * n, p)[0], y0[0])]
    sol = mp.findroot(lambda *y: f(list(y), [list(y)] * n, p), y0)
    return [sol[i] for i in range(d)]


def hopf_point(f, y0, taus_of, p0, w0):
    """(p, omega, y*) with det Delta(i omega) = 0 near (p0, omega0)."""
    def eqs(p, w):
        y = equilibrium(f, y0, taus_of(p), p)
        c = mp.det(delta(jac_blocks(f, y, taus_of(p), p), taus_of(p), 1j * w))
        return [mp.re(c), mp.im(c)]
    p, w = mp.findroot(eqs, (p0, w0))
    return p, w, equilibrium(f, y0, taus_of(p), p)


def null_vector(M):
    """The unit vector v with M v = 0 (M singular, rank d - 1): from the SVD."""
    U, S, V = mp.svd_c(M)
    v = V.H[:, M.rows - 1]
    k = max(range(M.rows), key=lambda i: abs(v[i]))
    return v * (abs(v[k]) / v[k]) / mp.norm(v)


def first_lyapunov(f, y, taus, p, w):
    d, n = len(y), len(taus)
    blocks = jac_blocks(f, y, taus, p)
    lam = 1j * w
    v = null_vector(delta(blocks, taus, lam))
    u = null_vector(delta(blocks, taus, lam).H)
    u = u / mp.conj((u.H * delta(blocks, taus, lam, True) * v)[0])
    stack = lambda x, k: mp.matrix([x[c] * mp.exp(-k * lam * t) for t in [0] + list(taus) for c in range(d)])
    Phi, Phib = stack(v, 1), stack(v, 1).conjugate()
    h20 = mp.lu_solve(delta(blocks, taus, 2 * lam), multilinear(f, y, taus, p, [Phi, Phi], (1, 1)))
    h11 = mp.lu_solve(delta(blocks, taus, 0), multilinear(f, y, taus, p, [Phi, Phib], (1, 1)))
    H20 = stack(h20, 2)
    H11 = mp.matrix([h11[c] for _ in range(n + 1) for c in range(d)])
    total = (multilinear(f, y, taus, p, [Phi, Phib], (2, 1)) + multilinear(f, y, taus, p, [H20, Phib], (1, 1)) +
             2 * multilinear(f, y, taus, p, [H11, Phi], (1, 1)))
    c1 = (u.H * total)[0] / 2
    return c1, v, u, blocks


def wright_check():
    a0, w = mp.pi / 2, mp.pi / 2
    f = lambda y, z, a: [-a * z[0][0] * (1 + y[0])]
    c1, v, u, blocks = first_lyapunov(f, [mp.mpf(0)], [1], a0, w)
    # lambda'(a) = -u^H (d Delta / da) v, d Delta / da = e^{-lambda} (the B block is -a)
    dlam = -(u.H * mp.matrix([[mp.exp(-1j * w)]]) * v)[0]
    amplitude2 = 4 * abs(v[0]) ** 2 * (-mp.re(dlam) / mp.re(c1))  # per unit a - pi/2
    known = 40 / (3 * mp.pi - 2)
    assert abs(amplitude2 - known) < mp.mpf(10) ** -30, (amplitude2, known)
    return c1, w


def main():
    c1, w = wright_check()
    print(f"wright a = pi/2: omega = {mp.nstr(w, 20)}, l1 = {mp.nstr(mp.re(c1) / w, 20)} "
          f"(amplitude^2 / (a - pi/2) = 40 / (3 pi - 2): checked)")

    # Hutchinson x' = r x (1 - x(t - 1)), the equation model of the tests: equilibrium x = 1
    f = lambda y, z, r: [r * y[0] * (1 - z[0][0])]
    r, w, y = hopf_point(f, [mp.mpf(1)], lambda r: [1], mp.mpf(1.5), mp.mpf(1.5))
    c1 = first_lyapunov(f, y, [1], r, w)[0]
    print(f"hutchinson: r = {mp.nstr(r, 20)}, omega = {mp.nstr(w, 20)}, l1 = {mp.nstr(mp.re(c1) / w, 20)}")

    # Mackey-Glass (built-in): beta 0.2, gamma 0.1, n 10, in tau; its first two Hopf points
    beta, gamma, n = mp.mpf("0.2"), mp.mpf("0.1"), 10
    f = lambda y, z, tau: [beta * z[0][0] / (1 + z[0][0] ** n) - gamma * y[0]]
    for tau0 in (4.7, 21.4):
        tau, w, y = hopf_point(f, [mp.mpf(1)], lambda tau: [tau], mp.mpf(tau0), mp.sqrt(mp.mpf("0.15")))
        c1 = first_lyapunov(f, y, [tau], tau, w)[0]
        print(f"mackey-glass: tau = {mp.nstr(tau, 20)}, omega = {mp.nstr(w, 20)}, l1 = {mp.nstr(mp.re(c1) / w, 20)}")

    # Lang-Kobayashi in real form (issue 61): alpha 3, C 0, tau 2, Tc 20, kappa 0.3, in P, from E = 0;
    # here at the lasing state's Hopf points is not needed: the off state's Hopf point
    alpha, kappa, Tc, tau = 3, mp.mpf("0.3"), 20, 2

    def lk(y, z, P):
        Ex, Ey, Nc = y
        ex, ey = z[0][0], z[0][1]
        return [Nc * (Ex - alpha * Ey) + kappa * ex, Nc * (Ey + alpha * Ex) + kappa * ey,
                (P - Nc - (1 + 2 * Nc) * (Ex * Ex + Ey * Ey)) / Tc]
    P, w, y = hopf_point(lk, [mp.mpf(0), mp.mpf(0), mp.mpf("-0.2")], lambda P: [tau], mp.mpf("-0.2"), mp.mpf("0.4"))
    c1 = first_lyapunov(lk, y, [tau], P, w)[0]
    print(f"lang-kobayashi: P = {mp.nstr(P, 20)}, omega = {mp.nstr(w, 20)}, l1 = {mp.nstr(mp.re(c1) / w, 20)}")


if __name__ == "__main__":
    main()

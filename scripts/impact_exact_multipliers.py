#!/usr/bin/python3
"""High-precision reference Floquet multipliers of the soft-impact oscillator at tau = T.

Independent of delayspec (no delayspec code or output is used). Model (model_impact.hpp):
  x' = v,  v' = a w^2 sin(w t) + k (v(t - tau) - v(t)) - 2 zeta v - x - beta (x - e) H(x - e)

Orbit. With tau = T = 2 pi / w the control k (v(t - T) - v(t)) vanishes on every T-periodic
orbit, so the orbit is the k = 0 periodic orbit of a piecewise-linear forced oscillator, the
same for all k. In each region (contact x > e, free x < e) the ODE is linear with constant
coefficients, so the flow is closed form: y(t) = yp(t) + expm(A (t - t0)) (y0 - yp(t0)), yp
the sinusoidal (+ constant beta e / (1 + beta) in contact) particular solution. Unknowns: the
crossing times t_i of x = e in one period and the velocities v_i there; equations: the arc
from (t_i, e, v_i) reaches (t_{i+1}, e, v_{i+1}) (t_{m+1} = t_1 + T). Guesses: float shooting
(fsolve on the solve_ivp period map from --start); mpmath.findroot refines them. (Plain
simulation from (0, 0) does NOT settle on this near-grazing orbit: its basin is tiny.)
The orbit is verified by dense sampling of x - e inside each arc (sign must not change).

Multipliers. The field is continuous across x = e (contact force 0 there), so there is no
saltation; only the Jacobian jumps. A Floquet solution has y(t - T) = y(t) / mu, so along the
orbit y' = (A_j + z B) y with z = 1/mu, A_j = [[0, 1], [-1 - beta [contact], -k - 2 zeta]],
B = [[0, 0], [0, k]]. With M(z) = prod_j expm((A_j + z B) dt_j) (last arc on the left) = Phi(mu),
mu is a multiplier iff det(Phi(mu) - mu I) = 0, i.e. iff h(z) = det(z M(z) - I) = 0. h is
entire in z (h(0) = 1; det M(z) = exp(T (z k - k - 2 zeta)) exactly), so the argument
principle on |z| = rho counts ALL multipliers with |mu| > 1/rho; the contour moments
sum z_i^p give the roots (Hankel pencil), which mpmath.findroot then polishes. (The mu -> 0
accumulation of the DDE spectrum is z -> infinity here.) At k = 0, h is a quadratic whose
roots are the inverse eigenvalues of the ODE monodromy: printed as a consistency check.

Run:  /usr/bin/python3 scripts/impact_exact_multipliers.py [--k 0.2,0.55,1.0,1.25]
        [--e 1.26] [--count 4] [--json]   (other parameters: --zeta --a --beta --omega)
"""
import argparse, json
import numpy as np
import mpmath as mp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, fsolve

mp.mp.dps = 40


def expm2(X):  # closed-form exp of a 2x2 matrix [[a, b], [c, d]] (nested tuples)
    (a, b), (c, d) = X
    s = (a + d) / 2
    q = mp.sqrt(((a - d) / 2) ** 2 + b * c)
    ch, sh = mp.cosh(q), (mp.sinh(q) / q if q != 0 else mp.mpf(1))
    es = mp.exp(s)
    return ((es * (ch + sh * (a - s)), es * sh * b), (es * sh * c, es * (ch + sh * (d - s))))


def mul2(X, Y):
    return tuple(tuple(sum(X[i][l] * Y[l][j] for l in range(2)) for j in range(2)) for i in range(2))


class Impact:
    def __init__(s, zeta, e, a, beta, omega):
        s.zeta, s.e, s.a, s.beta, s.w = (mp.mpf(v) for v in (zeta, e, a, beta, omega))
        s.T = 2 * mp.pi / s.w

    def c(s, j):  # stiffness in region j (1 = contact)
        return 1 + s.beta * j

    def yp(s, j, t):  # particular solution: x'' + 2 zeta x' + c x = a w^2 sin(w t) + beta e j
        c, w = s.c(j), s.w
        D = (c - w * w) ** 2 + (2 * s.zeta * w) ** 2
        P, Q = s.a * w * w * (c - w * w) / D, -s.a * w * w * 2 * s.zeta * w / D
        sn, cs = mp.sin(w * t), mp.cos(w * t)
        return (s.beta * s.e * j / c + P * sn + Q * cs, w * (P * cs - Q * sn))

    def flow(s, j, t0, y0, t1):
        dt = t1 - t0
        E = expm2(((0, dt), (-s.c(j) * dt, -2 * s.zeta * dt)))
        p0, p1 = s.yp(j, t0), s.yp(j, t1)
        d = (y0[0] - p0[0], y0[1] - p0[1])
        return tuple(mp.re(p1[i] + E[i][0] * d[0] + E[i][1] * d[1]) for i in range(2))

    def guess(s, y0):  # float shooting at k = 0 (fsolve on the period map), crossings of x = e
        a, b, z, w, e = (float(v) for v in (s.a, s.beta, s.zeta, s.w, s.e))
        f = lambda t, y: [y[1], a * w * w * np.sin(w * t) - 2 * z * y[1] - y[0] - b * max(y[0] - e, 0)]
        T = float(s.T)
        run = lambda y, dense=False: solve_ivp(f, (0, T), y, 'DOP853', rtol=1e-12, atol=1e-13, dense_output=dense)
        y = fsolve(lambda y: run(y).y[:, -1] - y, y0, xtol=1e-12)
        sol = run(y, True).sol
        ts = np.linspace(0, T, 40001)
        g = sol(ts)[0] - e
        idx = np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0]
        tc = [brentq(lambda t: sol(t)[0] - e, ts[i], ts[i + 1], xtol=1e-14) for i in idx]
        return [(t, sol(t)[1]) for t in tc]

    def orbit(s, guess):
        m = len(guess)
        if m == 0:  # no contact: the free linear periodic solution (verified below)
            return [], [(0, s.T)]
        regions = [1 if v > 0 else 0 for _, v in guess]

        def F(*u):
            t, v = list(u[:m]) + [u[0] + s.T], list(u[m:]) + [u[m]]
            r = []
            for i in range(m):
                y = s.flow(regions[i], t[i], (s.e, v[i]), t[i + 1])
                r += [y[0] - s.e, y[1] - v[i + 1]]
            return r
        u = mp.findroot(F, [mp.mpf(t) for t, _ in guess] + [mp.mpf(v) for _, v in guess])
        t, v = [u[i] for i in range(m)], [u[m + i] for i in range(m)]
        res = max(abs(r) for r in F(*u))
        arcs, pts = [], []
        for i in range(m):
            t1 = t[i + 1] if i + 1 < m else t[0] + s.T
            arcs.append((regions[i], t1 - t[i]))
            pts.append(dict(t=t[i], v=v[i], enter=bool(regions[i]), t_end=t1, res=res))
        return pts, arcs

    def verify(s, pts, arcs, n=2000):  # x - e keeps the region's sign inside every arc
        t0 = pts[0]['t'] if pts else mp.mpf(0)
        y0 = (s.e, pts[0]['v']) if pts else s.yp(0, t0)
        extreme = []
        for j, dt in arcs:
            xs = [s.flow(j, t0, y0, t0 + dt * i / n)[0] - s.e for i in range(1, n)]
            sign = 1 if j else -1
            assert all(sign * x > 0 for x in xs), "orbit crosses x = e inside an arc"
            extreme.append(max(xs) if j else min(xs))
            y0, t0 = s.flow(j, t0, y0, t0 + dt), t0 + dt
        return extreme

    def M(s, z, k, arcs):
        P = ((1, 0), (0, 1))
        for j, dt in arcs:
            P = mul2(expm2(((0, dt), ((-s.c(j)) * dt, (z * k - k - 2 * s.zeta) * dt))), P)
        return P

    def h(s, z, k, arcs):  # det(z M - I) with the exact det M
        P = s.M(z, k, arcs)
        return z * z * mp.exp(s.T * (z * k - k - 2 * s.zeta)) - z * (P[0][0] + P[1][1]) + 1

    def char(s, mu, k, arcs):  # det(Phi(mu) - mu I), computed directly as a residual check
        P = s.M(1 / mu, k, arcs)
        return (P[0][0] - mu) * (P[1][1] - mu) - P[0][1] * P[1][0]

    def roots_in_disc(s, k, arcs, rho, n=512):
        """All zeros of h in |z| < rho via contour moments; None if the count is not clean."""
        extra = int(float(abs(k) * rho * s.T) / 2.3) + 5  # digits lost to growth of M
        with mp.workdps(mp.mp.dps + extra):
            dz = mp.mpf(10) ** (-(mp.mp.dps // 3))
            mom = [mp.mpc(0)] * 40
            for i in range(n):
                z = rho * mp.expjpi(mp.mpf(2 * i) / n)
                g = (s.h(z + dz, k, arcs) - s.h(z - dz, k, arcs)) / (2 * dz) / s.h(z, k, arcs)
                wp = z * g / n
                for p in range(40):
                    mom[p] += wp
                    wp *= z / rho
            N = int(mp.nint(mp.re(mom[0])))
            if abs(mom[0] - N) > 1e-10 or 2 * N + 1 > len(mom):
                return None
            if N == 0:
                return []
            H0 = mp.matrix([[mom[i + j] for j in range(N)] for i in range(N)])
            H1 = mp.matrix([[mom[i + j + 1] for j in range(N)] for i in range(N)])
            w = mp.eig(H0 ** -1 * H1, left=False, right=False) if N > 1 else [mom[1] / mom[0]]
            zs = [mp.findroot(lambda z: s.h(z, k, arcs), rho * wi, verify=False) for wi in w]
        distinct = all(abs(a - b) > 1e-12 for i, a in enumerate(zs) for b in zs[:i])
        if not distinct or any(abs(z) >= rho for z in zs):
            return None
        return sorted(zs, key=abs)

    def multipliers(s, k, arcs, count):
        rho, rho_max = mp.mpf(1.5), mp.mpf(60)
        while True:
            zs = s.roots_in_disc(k, arcs, rho)
            if zs is not None and (len(zs) >= count or rho * 1.35 > rho_max):
                break
            rho *= 1.35 if zs is not None else 1.07
        zs = sorted(zs, key=lambda z: (round(float(abs(z)), 12), float(mp.im(z))))
        out = []
        for z in zs[:count]:
            mu = 1 / z
            out.append(dict(mu=mu, abs=abs(mu), res_char=abs(s.char(mu, k, arcs)), res_h=abs(s.h(z, k, arcs))))
        return out, len(zs), 1 / rho


def fmt(x, d=20):
    return mp.nstr(x, d)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--k', default='0.2,0.55,1.0,1.25')
    ap.add_argument('--count', type=int, default=4)
    ap.add_argument('--start', default='0,0', help='x,v at t = 0 to start the shooting guess from')
    ap.add_argument('--json', action='store_true')
    for name, val in (('zeta', '0.01'), ('e', '1.26'), ('a', '0.7'), ('beta', '28'), ('omega', '0.802')):
        ap.add_argument('--' + name, default=val)
    o = ap.parse_args()
    s = Impact(o.zeta, o.e, o.a, o.beta, o.omega)
    pts, arcs = s.orbit(s.guess([float(v) for v in o.start.split(',')]))
    extreme = s.verify(pts, arcs)
    eig0 = sorted(mp.eig(mp.matrix(s.M(0, 0, arcs)), left=False, right=False), key=lambda m: -mp.im(m))
    k0, _, _ = s.multipliers(0, arcs, 2)
    result = dict(
        parameters=dict(zeta=o.zeta, e=o.e, a=o.a, beta=o.beta, omega=o.omega, T=fmt(s.T)),
        orbit=dict(contact_intervals=sum(1 for p in pts if p['enter']),
                   crossings=[dict(t=fmt(p['t']), v=fmt(p['v']), enter=p['enter']) for p in pts],
                   arcs=[dict(contact=bool(j), duration=fmt(dt)) for j, dt in arcs],
                   max_penetration=[fmt(x, 12) for x, (j, _) in zip(extreme, arcs) if j],
                   residual=fmt(pts[0]['res'], 3) if pts else '0'),
        check_k0=dict(monodromy_eigs=[fmt(m) for m in eig0], roots=[fmt(r['mu']) for r in k0],
                      det=fmt(k0[0]['mu'] * k0[1]['mu']), det_expected=fmt(mp.exp(-2 * s.zeta * s.T))),
        k={})
    for k in o.k.split(','):
        mus, n, r = s.multipliers(mp.mpf(k), arcs, o.count)
        result['k'][k] = dict(roots_found=n, all_roots_with_abs_above=fmt(r, 6), multipliers=[
            dict(mu=fmt(m['mu']), re=fmt(mp.re(m['mu'])), im=fmt(mp.im(m['mu'])), abs=fmt(m['abs']), res_char=fmt(m['res_char'], 3), res_h=fmt(m['res_h'], 3))
            for m in mus])
    if o.json:
        print(json.dumps(result, indent=1))
        return
    print('T =', result['parameters']['T'])
    for key, val in result['orbit'].items():
        print(f'orbit {key}: {val}')
    print('check k = 0: monodromy eigs', result['check_k0']['monodromy_eigs'])
    print('             roots of h   ', result['check_k0']['roots'], ' product', result['check_k0']['det'],
          '= exp(-2 zeta T)?', result['check_k0']['det_expected'])
    for k, r in result['k'].items():
        print(f"k = {k}: {r['roots_found']} roots with |mu| > {r['all_roots_with_abs_above']}, leading:")
        for m in r['multipliers']:
            print(f"  mu = {m['mu']:>50}  |mu| = {m['abs']}  res det(Phi-mu I) = {m['res_char']}  res h = {m['res_h']}")


if __name__ == '__main__':
    main()

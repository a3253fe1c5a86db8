"""Independent reference model (written for this project's tests, from the paper's
equations, without reading the kernel): off-bottom torsional start-up with distributed
Coulomb side friction (after Aarsnes & Shor, J. Pet. Sci. Eng. 163 (2018) 712-721,
eqs. (1)-(10): wave equation with a set-valued friction inclusion, PI top drive).

Numerical method (deliberately NOT the method of characteristics):
  * lumped-mass / linear-spring chain (node-based FE with lumped mass): each
    section is cut into elements of length <= dx_m; an element is a torsional
    spring G*J/h; each node carries half of the inertia rho*J*h of its two
    neighbouring elements, node 0 also carries the top-drive inertia, the last
    node also carries J_bit;
  * side friction is lumped at every node: static / dynamic capacity
    Fs_j = mu_s * int_{trib(j)} r_o N dx over the node's tributary length, N the
    soft string's |T inc' - (rho - rho_mud) A g sin(inc)| (weight and the tension
    x build term of its 2-D well, T the hanging tension; ``friction_cumulative``),
    Fd_j likewise;
  * time stepping: symplectic (semi-implicit) Euler -- velocities from the
    elastic + motor torques at the old angles, angles from the new velocities;
    viscous damping implicit; friction as an impulse at the velocity level
    (Moreau-type time stepping): with F_req = I w/dt + T (the torque that
    would stop the node in this step)
        |F_req| <= limit  ->  w_new = 0            (stuck, set-valued)
        otherwise         ->  w_new = (F_req - limit sign F_req)/(I/dt + c)
    limit = Fs when |w_old| <= omega_s (Karnopp stick band), Fd otherwise.
    That is stick_law="impulse" (DEFAULT): stuck <=> the torque that holds the
    node at rest in this step is within the capacity -- the lumped analogue of
    Aarsnes & Shor's inclusion (their F~, eq. 20-22).  Option
    stick_law="karnopp_snap" additionally snaps a node that is still moving
    inside the band to rest whenever its elastic torque is within Fs:
        |w_old| <= omega_s and |T| <= Fs -> w_new = 0 (stuck, friction = T)
        |w_old| <= omega_s and |T| >  Fs -> slip with capacity Fs opposing w_new
                                            (stops if Fs can stop it in one step)
        |w_old| >  omega_s               -> slide, friction Fd opposing w_new
                                            (implicit: stops at 0 if Fd can hold it)
    (T = elastic + motor torque on the node).  No smoothing/regularisation.
  * the bit node is clamped w_bit >= 0 after each step (as the project does).

Usage: python reference_startup.py inputs.json  -> prints result JSON.
Optional numeric keys in inputs: "dx_m" (default 2.0), "cfl" (default 0.5),
"return_series" (bool), "stick_law" ("impulse" | "karnopp_snap").  Optional
per-section "shear_modulus_pa", "density_kg_m3" override the global values.
"""
import itertools
import json
import math
import sys

import numpy as np

try:
    import numba
    _HAVE_NUMBA = True
except Exception:  # pragma: no cover
    _HAVE_NUMBA = False

G0 = 9.80665
RPM = 2.0 * math.pi / 60.0


# ----------------------------------------------------------------------------
# geometry / friction helpers (also used by the analytic checks)
# ----------------------------------------------------------------------------
def sections_table(inp):
    rho0 = float(inp.get("density_kg_m3", 7850.0))
    G0_ = float(inp.get("shear_modulus_pa", 79.3e9))
    secs = []
    x = 0.0
    for s in inp["sections"]:
        ro, ri, L = float(s["outer_radius_m"]), float(s["inner_radius_m"]), float(s["length_m"])
        rho = float(s.get("density_kg_m3", rho0))
        G = float(s.get("shear_modulus_pa", G0_))
        secs.append(dict(x0=x, x1=x + L, L=L, ro=ro, ri=ri, rho=rho, G=G,
                         J=0.5 * math.pi * (ro ** 4 - ri ** 4),
                         A=math.pi * (ro ** 2 - ri ** 2)))
        x += L
    return secs


def _survey(inp):
    sv = sorted(inp["survey"], key=lambda p: p["md_m"])
    md = np.array([p["md_m"] for p in sv], float)
    inc = np.radians(np.array([p["inclination_deg"] for p in sv], float))
    return md, inc


def inclination(inp, x):
    md, inc = _survey(inp)
    return np.interp(x, md, inc)  # linear in MD, held constant outside


def friction_cumulative(inp, x, mu=1.0, cell_m=0.25):
    """W(x) = int_0^x mu r_o N dx [N m]: N the soft string's normal force per metre in
    its 2-D well, |T inc' - w sin(inc)| (w = (rho - rho_mud) A g; tension T along the
    curved path pulls it towards the centre of the build, the high side, against the
    weight's part across the hole), T(x) = int_x^L w cos(inc) the string hanging off
    bottom; midpoint rule on cells of at most ``cell_m`` between the breakpoints (survey
    points and section ends), where inc is linear."""
    secs = sections_table(inp)
    md, inc_pts = _survey(inp)
    rho_m = float(inp.get("mud_density_kg_m3", 0.0))
    Ltot = secs[-1]["x1"]
    bps = {0.0, Ltot}
    for sec in secs:
        bps.update((sec["x0"], sec["x1"]))
    bps.update(float(m) for m in md if 0.0 < m < Ltot)
    bps = np.array(sorted(bps))
    edges = np.concatenate([np.linspace(a, b, max(1, math.ceil((b - a) / cell_m)) + 1)[:-1]
                            for a, b in itertools.pairwise(bps)] + [bps[-1:]])
    mids, h = 0.5 * (edges[:-1] + edges[1:]), np.diff(edges)
    w, ro = np.empty(mids.size), np.empty(mids.size)
    for sec in secs:
        inside = (mids >= sec["x0"]) & (mids <= sec["x1"])
        w[inside] = (sec["rho"] - rho_m) * sec["A"] * G0
        ro[inside] = sec["ro"]
    th = inclination(inp, mids)
    slopes = np.diff(inc_pts) / np.diff(md)
    leg = np.searchsorted(md, mids, side="right") - 1
    build = np.where(leg < len(slopes), slopes[np.clip(leg, 0, len(slopes) - 1)], 0.0)
    below = np.cumsum((w * np.cos(th) * h)[::-1])[::-1]            # T at each cell's top
    tension = below - 0.5 * w * np.cos(th) * h                     # ... and at its middle
    normal = np.abs(tension * build - w * np.sin(th))
    cum = np.concatenate([[0.0], np.cumsum(ro * normal * h)])
    return mu * np.interp(np.clip(np.asarray(x, float), 0.0, Ltot), edges, cum)


def analytic(inp, n_quad=200000):
    """Closed-form reference numbers of the quasi-static problem."""
    secs = sections_table(inp)
    sf = inp["side_friction"]
    Ltot = secs[-1]["x1"]
    Ws_L = float(friction_cumulative(inp, Ltot, sf["static"]))
    Wd_L = float(friction_cumulative(inp, Ltot, sf["dynamic"]))
    # twist at break-away: int_0^L T(x)/(G J) dx, T(x) = Ws(L) - Ws(x)
    twist = 0.0
    for s in secs:
        xs = np.linspace(s["x0"], s["x1"], max(2001, int(n_quad * s["L"] / Ltot)))
        T = Ws_L - friction_cumulative(inp, xs, sf["static"])
        twist += np.trapezoid(T, xs) / (s["G"] * s["J"])
    gam = float(inp.get("torsional_damping_per_s", 0.0))
    w = float(inp["rpm"]) * RPM
    visc = sum(gam * s["rho"] * s["J"] * s["L"] * w for s in secs)
    c = [math.sqrt(s["G"] / s["rho"]) for s in secs]
    t_wave = sum(s["L"] / ci for s, ci in zip(secs, c, strict=False))
    return dict(static_breakaway_torque_nm=Ws_L, dynamic_sliding_torque_nm=Wd_L,
                viscous_torque_nm=visc, sliding_torque_nm=Wd_L + visc,
                breakaway_twist_turns=twist / (2 * math.pi),
                one_way_wave_time_s=t_wave)


# ----------------------------------------------------------------------------
# discretisation
# ----------------------------------------------------------------------------
def build_chain(inp, dx_m, cfl):
    secs = sections_table(inp)
    sf = inp["side_friction"]
    xs = [0.0]
    k_el, Iel, _cel = [], [], []
    hmin_over_c = 1e9
    gam = float(inp.get("torsional_damping_per_s", 0.0))
    for s in secs:
        n = max(1, math.ceil(s["L"] / dx_m - 1e-9))
        h = s["L"] / n
        c = math.sqrt(s["G"] / s["rho"])
        hmin_over_c = min(hmin_over_c, h / c)
        for i in range(n):
            xs.append(s["x0"] + (i + 1) * h)
            k_el.append(s["G"] * s["J"] / h)
            Iel.append(s["rho"] * s["J"] * h)
    xs = np.array(xs)
    xs[-1] = secs[-1]["x1"]
    k_el = np.array(k_el)
    Iel = np.array(Iel)
    M = len(k_el)  # nodes 0..M
    Istr = np.zeros(M + 1)
    Istr[:-1] += 0.5 * Iel
    Istr[1:] += 0.5 * Iel
    Inode = Istr.copy()
    Inode[0] += float(inp["top_drive"]["inertia_kg_m2"])
    Inode[-1] += float(inp.get("bit_inertia_kg_m2", 0.0))
    cvisc = gam * Istr
    # tributary bounds
    lo = np.concatenate([[xs[0]], 0.5 * (xs[:-1] + xs[1:])])
    hi = np.concatenate([0.5 * (xs[:-1] + xs[1:]), [xs[-1]]])
    W1 = friction_cumulative(inp, np.concatenate([lo, hi]), 1.0)
    Ftrib = W1[M + 1:] - W1[:M + 1]
    Fs = float(sf["static"]) * Ftrib
    Fd = float(sf["dynamic"]) * Ftrib
    dt_max = cfl * hmin_over_c
    return dict(x=xs, k=k_el, I=Inode, c=cvisc, Fs=Fs, Fd=Fd, dt_max=dt_max, M=M)


# ----------------------------------------------------------------------------
# time-stepping kernel
# ----------------------------------------------------------------------------
def _kernel_py(nsteps, stride, dt, k, I, c, Fs, Fd, ws, wref_final, ramp_s,  # noqa: E741
               kp, ki, tmax, law, phi, w, out):
    """out[:, 0..6] = t, w_td, w_bit, motor, T_top, phi_td, phi_bit (sampled).
    ev = [t_break, phi_td@break, Ttop@break, t_slip, peak_motor, I_int]"""
    M = k.shape[0]
    tau = np.empty(M)
    Tn = np.empty(M + 1)
    Iint = 0.0
    t_break = -1.0
    phi_b = 0.0
    T_b = 0.0
    t_slip = -1.0
    peak = -1e300
    thr1 = 1.0 * 2.0 * math.pi / 60.0
    thr30 = 30.0 * 2.0 * math.pi / 60.0
    isamp = 0
    for n in range(nsteps + 1):
        t = n * dt
        wr = wref_final * min(t / ramp_s, 1.0) if ramp_s > 0.0 else wref_final
        e = wr - w[0]
        u = kp * e + Iint
        m = min(max(u, -tmax), tmax)
        for j in range(M):
            tau[j] = k[j] * (phi[j] - phi[j + 1])
        if n % stride == 0:
            out[isamp, 0] = t
            out[isamp, 1] = w[0]
            out[isamp, 2] = w[M]
            out[isamp, 3] = m
            out[isamp, 4] = tau[0]
            out[isamp, 5] = phi[0]
            out[isamp, 6] = phi[M]
            isamp += 1
        if m > peak:
            peak = m
        if t_break < 0.0 and w[M] > thr1:
            t_break = t
            phi_b = phi[0]
            T_b = tau[0]
        if t_slip < 0.0 and w[M] > thr30:
            t_slip = t
        if n == nsteps:
            break
        # PI integral with anti-windup (held while saturated in the error's direction)
        if not ((u >= tmax and e > 0.0) or (u <= -tmax and e < 0.0)):
            Iint += ki * e * dt
            Iint = min(max(Iint, -tmax), tmax)
        # nodal torques
        Tn[0] = m - tau[0]
        for j in range(1, M):
            Tn[j] = tau[j - 1] - tau[j]
        Tn[M] = tau[M - 1]
        for j in range(M + 1):
            wj = w[j]
            den = I[j] / dt + c[j]
            if law == 0:
                # "karnopp_snap": inside the band the node is also snapped to
                # rest whenever the net non-friction torque is within Fs
                if abs(wj) <= ws:
                    freq = I[j] * wj / dt + Tn[j]
                    if abs(Tn[j]) <= Fs[j] or abs(freq) <= Fs[j]:
                        wn = 0.0
                    # slipping inside the band: capacity Fs, opposing the new
                    # velocity (never along it -- no work done by friction)
                    elif freq > 0.0:
                        wn = (freq - Fs[j]) / den
                    else:
                        wn = (freq + Fs[j]) / den
                else:
                    # sliding: friction Fd opposing the (new) velocity; if the
                    # node would reach zero in this step and Fd can hold it,
                    # it stops (implicit Coulomb, no overshoot through zero)
                    freq = I[j] * wj / dt + Tn[j]
                    if abs(freq) <= Fd[j]:
                        wn = 0.0
                    elif freq > 0.0:
                        wn = (freq - Fd[j]) / den
                    else:
                        wn = (freq + Fd[j]) / den
            else:
                # law 1: one-step stopping impulse (Moreau; like the
                # inclusion F~ of Aarsnes & Shor eq. 20-22)
                freq = I[j] * wj / dt + Tn[j]
                lim = Fs[j] if abs(wj) <= ws else Fd[j]
                if abs(freq) <= lim:
                    wn = 0.0
                elif freq > 0.0:
                    wn = (freq - lim) / den
                else:
                    wn = (freq + lim) / den
            w[j] = wn
        if w[M] < 0.0:
            w[M] = 0.0
        for j in range(M + 1):
            phi[j] += dt * w[j]
    return np.array([t_break, phi_b, T_b, t_slip, peak, Iint])


_kernel = numba.njit(cache=True, fastmath=False)(_kernel_py) if _HAVE_NUMBA else _kernel_py


# ----------------------------------------------------------------------------
def _stats(a):
    return dict(mean=float(np.mean(a)), min=float(np.min(a)), max=float(np.max(a)))


def postprocess(ts, wbit, motor, twist_turns, seconds):
    half = ts >= 0.5 * seconds - 1e-12
    t2, wb2 = ts[half], wbit[half]
    stuck = wb2 < 1.0 * RPM
    dt_s = ts[1] - ts[0] if len(ts) > 1 else 0.0
    # slips that follow a stick (bit < 1 rpm) lasting >= 0.5 s
    onsets = []
    run_start = None
    for i in range(len(t2)):
        if stuck[i]:
            if run_start is None:
                run_start = t2[i]
        else:
            if run_start is not None:
                if t2[i] - run_start >= 0.5 - 1e-9:
                    onsets.append(t2[i])
                run_start = None
    period = float(np.mean(np.diff(onsets))) if len(onsets) >= 2 else None
    return dict(stick_slip=bool(len(onsets) >= 1), period_s=period,
                n_slips=len(onsets),
                stick_fraction=float(np.mean(stuck)),
                bit_rpm_max=float(np.max(wb2) / RPM),
                motor_torque_nm=_stats(motor[half]),
                twist_turns=_stats(twist_turns[half]),
                _sample_dt=dt_s)


def reference_startup(inputs: dict) -> dict:
    inp = inputs
    dx_m = float(inp.get("dx_m", 2.0))
    cfl = float(inp.get("cfl", 0.5))
    law = {"karnopp_snap": 0, "impulse": 1}[inp.get("stick_law", "impulse")]
    ch = build_chain(inp, dx_m, cfl)
    seconds = float(inp["seconds"])
    fs = float(inp.get("sample_hz", 100.0))
    stride = math.ceil((1.0 / fs) / ch["dt_max"])
    dt = 1.0 / (fs * stride)
    nsamp = round(seconds * fs)
    nsteps = nsamp * stride
    td = inp["top_drive"]
    M = ch["M"]
    phi = np.zeros(M + 1)
    w = np.zeros(M + 1)
    out = np.zeros((nsamp + 1, 7))
    ev = _kernel(nsteps, stride, dt, ch["k"], ch["I"], ch["c"], ch["Fs"], ch["Fd"],
                 float(inp["side_friction"]["stick_speed_rad_s"]),
                 float(inp["rpm"]) * RPM, float(inp.get("ramp_s", 0.0)),
                 float(td["kp_nm_s"]), float(td["ki_nm"]), float(td["max_torque_nm"]),
                 law, phi, w, out)
    ts, wtd, wbit, motor, Ttop, ptd, pbit = out.T
    twist = (ptd - pbit) / (2 * math.pi)
    res = dict(
        breakaway_s=None if ev[0] < 0 else float(ev[0]),
        breakaway_turns=None if ev[0] < 0 else float(ev[1] / (2 * math.pi)),
        breakaway_torque_nm=None if ev[0] < 0 else float(ev[2]),
        first_slip_s=None if ev[3] < 0 else float(ev[3]),
        peak_motor_torque_nm=float(ev[4]),
    )
    # robust variant: first sample from which the bit stays above 1 rpm for 0.25 s
    above = wbit > 1.0 * RPM
    win = max(1, round(0.25 * fs))
    sus = None
    for i in range(len(ts) - win):
        if above[i] and above[i:i + win + 1].all():
            sus = i
            break
    res["breakaway_sustained"] = None if sus is None else dict(
        t_s=float(ts[sus]), turns=float(ptd[sus] / (2 * math.pi)), torque_nm=float(Ttop[sus]))
    pp = postprocess(ts, wbit, motor, twist, seconds)
    res.update({k: v for k, v in pp.items() if not k.startswith("_")})
    res["_numerics"] = dict(method="lumped FE chain, symplectic Euler, set-valued nodal friction",
                            stick_law=inp.get("stick_law", "impulse"),
                            dx_m=dx_m, cfl=cfl, dt_s=dt, nodes=M + 1,
                            numba=_HAVE_NUMBA,
                            top_drive_rpm_final=float(wtd[-1] / RPM),
                            string_top_torque_last_nm=float(Ttop[-1]))
    if inp.get("return_series"):
        res["_series"] = dict(t=ts, w_td=wtd, w_bit=wbit, motor=motor, T_top=Ttop,
                              twist_turns=twist, phi_td=ptd)
    return res


def main(argv):
    with open(argv[1]) as f:
        inp = json.load(f)
    res = reference_startup(inp)
    res.pop("_series", None)
    print(json.dumps(res, indent=2))


if __name__ == "__main__":
    main(sys.argv)

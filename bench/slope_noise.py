#!/usr/bin/python3
"""How noisy is the CPI slope, and how could it be made less noisy? Reads the committed direct
ensembles (plain DEM, no jumps; every member's light ICDF every 0.5 time units), cuts them after the
start-up transient into consecutive non-overlapping windows (start + kW, start + (k+1)W] and fits
every member's least-squares slope per p-node in each, then reports:

  1. SE(W) = std_r(s)/sqrt(R) against W and the exponent a of Var(SE) ~ W^-a (white noise 3,
     random-walk-like noise 1); per pair the measured noise of the ensemble-mean slope (a - b);
  2. the correlation of the members' slope deviations d = s - mean_r s across windows (lags 1-3)
     and the variance of the mean of m successive d compared with 1/m;
  3. the share of the deviation variance that other coordinates remove (ICDF - own centre of mass,
     ICDF - node mean, principal components, the best per-node multiple of the centre of mass);
  4. the slope (signal) against its noise per W;
  5. an emulated jump: the prediction X(t_k) + DT * (mean of the last m window slopes) against the
     realised change of the same ensemble and of the independent other one (pairs a, b), the
     realised change's own noise measured from a - b and subtracted;
  6. ranks in the whole bed r_i = F_bed(q_i) (files with bed/solid_fraction, --bed-files): their
     slope noise against the heights' in a common unit, and the slopes' signal-to-noise.

    /usr/bin/python3 bench/slope_noise.py [--out bench/results/slope_noise] [--bed-files F.h5 ...]

Writes slope_noise.md and slope_noise.png into --out; runs in seconds.
"""
import argparse
import os

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RES = os.path.join(HERE, "results")
CASES = [("demo U0.19 R8", "adaptive_study_r8/u0.19"), ("demo U0.41 R8", "adaptive_study_r8/u0.41"),
         ("tall U0.19 R4", "tall_study_r4/u0.19"), ("tall U0.41 R4", "tall_study_r4/u0.41")]
WS = (5, 10, 20, 40)


def load(path):
    with h5py.File(path, "r") as f:
        t, icdf, com = f["samples/time"][:], f["samples/icdf"][:], f["samples/com"][:]
    ok = np.isfinite(icdf).all(axis=(1, 2)) & np.isfinite(com).all(axis=1)  # rows with NaN ignored
    t, icdf, com = t[ok], icdf[ok], com[ok]
    dt = float(np.median(np.diff(t)))
    tick = np.rint(t / dt).astype(int)
    return dict(path=os.path.relpath(path, os.path.join(HERE, "..")), dt=dt, tick=tick, icdf=icdf,
                com=com[:, :, None], R=icdf.shape[1], pos={int(k): i for i, k in enumerate(tick)})


def slopes(run, y, W, start, kind="ls"):
    """Members' slopes (K, R, nodes) of y (n, R, nodes) in the complete consecutive windows, and
    the index of each window's last sample (stops at the first window with a missing sample).
    kind "ls": least squares (as CPI); "end": (last - first sample) / time between them."""
    n, t0 = int(round(W / run["dt"])), int(round(start / run["dt"]))
    tt = np.arange(1, n + 1) * run["dt"]
    tc = tt - tt.mean()
    out, ends, k = [], [], 0
    while True:
        idx = [run["pos"].get(t0 + k * n + j) for j in range(1, n + 1)]
        if None in idx:
            break
        out.append(np.tensordot(tc, y[idx], axes=(0, 0)) / np.sum(tc * tc) if kind == "ls"
                   else (y[idx[-1]] - y[idx[0]]) / (tt[-1] - tt[0]))
        ends.append(idx[-1])
        k += 1
    return np.array(out), np.array(ends)


def dev(S):
    return S - S.mean(axis=1, keepdims=True)  # members' deviations from the ensemble-mean slope


def ms(x):
    return float(np.mean(np.square(x)))


def se2(S):
    return S.var(axis=1, ddof=1) / S.shape[1]  # SE^2 per window and node


def lag_corr(d, lag):
    a, b = d[:-lag], d[lag:]  # pooled over members, nodes and window pairs k, k+lag
    return float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b))) if len(b) else np.nan


def pool_factor(d, m):
    """Var(mean of m successive deviations) / Var(d): 1/m if the windows are independent."""
    pooled = np.array([d[k - m + 1:k + 1].mean(axis=0) for k in range(m - 1, len(d))])
    return ms(pooled) / ms(d) if len(pooled) else np.nan


def file_stats(run, start):
    """Items 1-4 for one direct file."""
    st = {"se": {}, "sig": {}, "K": {}}
    for W in WS:
        S, _ = slopes(run, run["icdf"], W, start)
        st["se"][W], st["sig"][W], st["K"][W] = float(np.mean(se2(S))), ms(S.mean(axis=1)), len(S)
    st["a"] = {(w1, w2): -np.log(st["se"][w2] / st["se"][w1]) / np.log(w2 / w1) for w1, w2 in zip(WS, WS[1:])}
    st["a_fit"] = -np.polyfit(np.log(WS), np.log([st["se"][w] for w in WS]), 1)[0]
    for W in (10, 20):  # item 2
        d = dev(slopes(run, run["icdf"], W, start)[0])
        st[("corr", W)] = [lag_corr(d, L) for L in (1, 2, 3)]
        st[("pool", W)] = [pool_factor(d, m) for m in (2, 4)]
    # item 3, W = 10: deviation variance sum_i Var_r(s_ri), averaged over windows, per coordinate
    y = run["icdf"]
    S = {name: slopes(run, v, 10, start)[0] for name, v in
         [("raw", y), ("com", y - run["com"]), ("nodemean", y - y.mean(axis=2, keepdims=True)), ("c", run["com"])]}
    vraw = S["raw"].var(axis=1, ddof=1).sum(axis=1).mean()
    S["end"] = slopes(run, y, 10, start, kind="end")[0]
    for name in ("com", "nodemean", "end"):
        st["rm_" + name] = 1 - S[name].var(axis=1, ddof=1).sum(axis=1).mean() / vraw
    d, dc = dev(S["raw"]), dev(S["c"])  # best per-node multiple beta_i of the centre of mass
    beta = np.sum(d * dc, axis=(0, 1)) / np.sum(dc * dc)
    st["rm_beta"], st["beta"] = 1 - ms(d - beta * dc) / ms(d), beta
    D = d.reshape(-1, d.shape[2])
    ev, vec = np.linalg.eigh(D.T @ D / (len(d) * (run["R"] - 1)))  # 19 x 19 covariance of deviations
    ev, vec = ev[::-1], vec[:, ::-1]
    st["pc_share"], st["pc1"] = ev / ev.sum(), vec[:, 0] * np.sign(vec[:, 0].sum())
    st["pc1_cos_uniform"] = abs(vec[:, 0].sum()) / np.sqrt(len(vec))
    st["vraw"], st["com_sig"], st["com_se"] = vraw, ms(S["c"].mean(axis=1)), float(np.mean(se2(S["c"])))
    st["D"] = D
    return st


def pair_stats(ra, rb, start):
    """Items 1/4 across the independent ensembles a, b: the noise of the ensemble-mean slope from
    (s_a - s_b)/sqrt(2), the signal from sqrt(mean s_a*s_b) (the noises are independent)."""
    out = {}
    for W in WS:
        sa, sb = (slopes(r, r["icdf"], W, start)[0] for r in (ra, rb))
        K = min(len(sa), len(sb))
        ma, mb = sa[:K].mean(axis=1), sb[:K].mean(axis=1)
        out[W] = (np.sqrt((float(np.mean(se2(sa[:K]))) + float(np.mean(se2(sb[:K])))) / 2), np.sqrt(ms(ma - mb) / 2),
                  np.sqrt(max(0.0, float(np.mean(ma * mb)))))
    return out


def jump_study(ra, rb, start, W=10, dts=(20, 40, 80), mset=(1, 2, 4)):
    """Item 5. Each ensemble predicts X(t_k + DT) - X(t_k) = DT * (mean of its last m window slopes);
    errors against its own realised change ('same') and the other ensemble's ('cross'); both
    directions pooled. The realised change carries the ensemble-mean noise eta; MS(eta) is measured
    as MS(dX_a - dX_b)/2 and subtracted from the cross error (the other ensemble's eta is
    independent of the prediction), leaving the error against the true mean change. That splits
    into DT * (measured slope noise, from s_a - s_b) and the rest (lag/curvature bias)."""
    S = [slopes(r, r["icdf"], W, start) for r in (ra, rb)]
    K = min(len(S[0][1]), len(S[1][1]))
    assert (ra["tick"][S[0][1][:K]] == rb["tick"][S[1][1][:K]]).all(), "a and b on different time grids"
    X = [r["icdf"].mean(axis=1) for r in (ra, rb)]
    slope = [s[0][:K].mean(axis=1) for s in S]
    sev = [se2(s[0][:K]) for s in S]
    rows = []
    for DT in dts:
        jt = int(round(DT / ra["dt"]))
        ks = [k for k in range(max(mset) - 1, K) if all(ra["tick"][S[0][1][k]] + jt in r["pos"] for r in (ra, rb))]
        i0 = [S[0][1][ks], S[1][1][ks]]
        i1 = [[r["pos"][int(ra["tick"][S[0][1][k]]) + jt] for k in ks] for r in (ra, rb)]
        dX = [X[e][i1[e]] - X[e][i0[e]] for e in (0, 1)]
        eta = ms(dX[0] - dX[1]) / 2
        var_end = np.mean([r["icdf"][i].var(axis=1, ddof=1).mean() / r["R"] for r in (ra, rb) for i in i0 + i1])
        for m in mset:
            pr = [DT * np.array([slope[e][k - m + 1:k + 1].mean(axis=0) for k in ks]) for e in (0, 1)]
            same = (ms(pr[0] - dX[0]) + ms(pr[1] - dX[1])) / 2
            cross = (ms(pr[0] - dX[1]) + ms(pr[1] - dX[0])) / 2
            noise = ms(pr[0] - pr[1]) / 2
            pred = DT**2 * np.mean([sev[e][k - m + 1:k + 1].mean() for e in (0, 1) for k in ks]) / m
            rows.append(dict(DT=DT, m=m, n=len(ks), same=same, cross=cross, eta=eta, corr=cross - eta,
                             noise=noise, pred=pred, bias=cross - eta - noise, ref=2 * var_end,
                             rw=1.2 * eta / DT / W * DT**2 / m))  # random walk: Var(LS slope) = 1.2 q / W
    return rows


# ---- 6. ranks in the whole bed (files written with observe.bed = true) ----------------------------
STUDY_BED = [os.path.join(RES, "slope_study_r4_u0.19_t600", f"direct_{x}.h5") for x in "bc"]


def load_bed(path):
    """Every member's light ICDF q_i, its rank among all particles r_i = F_bed(q_i) and its bed
    density f_bed = dF_bed/dz at the slab centres [1/d_p]. F_bed = cumulative solid fraction over
    the slabs, normalised to 1, each slab's volume spread uniformly over the slab (so F_bed is
    piecewise linear between the slab edges). F_bed weights sphere volume, q_i centres: a fixed
    monotone map of heights, all a rank coordinate needs. None if the file has no profile."""
    with h5py.File(path, "r") as f:
        if "bed/solid_fraction" not in f:
            return None
        t, q, phi, z = (f[k][:] for k in ("samples/time", "samples/icdf", "bed/solid_fraction", "bed/z"))
        dz = float(f["bed"].attrs.get("profile_dz", np.median(np.diff(z))))
        if "parameters" in f:  # a run file
            par = dict(ln.split("[")[0].split("=", 1) for ln in f["parameters"][()].decode().splitlines() if "=" in ln)
        else:  # a study's archived result: the command's key=value words
            cmd = f.attrs.get("study_command", b"")
            cmd = cmd.decode() if isinstance(cmd, bytes) else str(cmd)
            par = dict(w.split("=", 1) for w in cmd.split() if "=" in w)
    ok = np.isfinite(q).all(axis=(1, 2)) & np.isfinite(phi).all(axis=(1, 2))  # rows with NaN ignored
    t, q, phi = t[ok], q[ok], phi[ok]
    C = np.concatenate([np.zeros(phi.shape[:2] + (1,)), np.cumsum(phi, axis=2)], axis=2)
    C /= C[..., -1:]  # F_bed at the slab edges z[0] - dz/2 + j dz, j = 0..slabs
    x = np.clip((q - (z[0] - dz / 2)) / dz, 0, phi.shape[2] - 1e-9)  # q in slab units from the bottom edge
    j = x.astype(int)
    lo, hi = np.take_along_axis(C, j, 2), np.take_along_axis(C, j + 1, 2)
    dt = float(np.median(np.diff(t)))
    tick = np.rint(t / dt).astype(int)
    par = {k.strip(): v.strip() for k, v in par.items()}
    return dict(path=path, dt=dt, pos={int(k): i for i, k in enumerate(tick)}, icdf=q, ranks=lo + (x - j) * (hi - lo),
                dens=phi / (phi.sum(axis=2, keepdims=True) * dz), z=z, R=q.shape[1], T=float(t[-1]),
                U=par.get("gas_drag.superficial_velocity", "?"), N=par.get("bed.count", "?"))


def bed_stats(run, start):
    """Per W: the members' slope-deviation variance sum_i Var_r(s_i), averaged over windows, in
    heights [d_p^2/t^2], ranks [1/t^2] and ranks in height units (rank slope / f_bed(q_i), f_bed
    the window's ensemble- and time-mean density profile, linear between slab centres, at the
    window's mean q_i); the uniform-shift share of each (as section 3b: removed by subtracting
    the node mean); S/N = RMS ensemble-mean slope / RMS SE."""
    def var(S):
        return S.var(axis=1, ddof=1).sum(axis=1).mean()

    def unif(S):
        return 1 - var(S - S.mean(axis=2, keepdims=True)) / var(S)

    def snr(S):
        return np.sqrt(ms(S.mean(axis=1)) / np.mean(se2(S)))

    out = {}
    for W in (10, 20):
        Sh, ends = slopes(run, run["icdf"], W, start)
        Sr = slopes(run, run["ranks"], W, start)[0]
        if not len(Sh):
            continue
        n = int(round(W / run["dt"]))
        win = [slice(e - n + 1, e + 1) for e in ends]  # a window's samples (consecutive: none missing)
        f = np.array([np.interp(run["icdf"][w].mean(axis=(0, 1)), run["z"], run["dens"][w].mean(axis=(0, 1)))
                      for w in win])  # (windows, nodes) [1/d_p]
        Srh = Sr / f[:, None, :]
        node = 1 - Srh.var(axis=1, ddof=1).mean(axis=0) / Sh.var(axis=1, ddof=1).mean(axis=0)
        out[W] = dict(K=len(Sh), vh=var(Sh), vr=var(Sr), vrh=var(Srh), uh=unif(Sh), ur=unif(Srh),
                      sh=snr(Sh), sr=snr(Sr), srh=snr(Srh), node=node, f=f.mean(axis=0))
    return out


def rt(x):
    return f"{np.sqrt(x):.3g}" if x >= 0 else f"-{np.sqrt(-x):.3g}"  # signed sqrt: negative MS = noise


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(RES, "slope_noise"))
    ap.add_argument("--start", type=float, default=30.0, help="skip the start-up transient")
    ap.add_argument("--bed-files", nargs="*", default=[p for p in STUDY_BED if os.path.exists(p)],
                    help="direct files with bed/solid_fraction for section 6 (default: slope_study_r4_u0.19_t600 "
                         "direct_b/c.h5 when they exist)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    runs, stats, pairs, jumps = {}, {}, {}, {}
    for label, sub in CASES:
        for ab in "ab":
            p = os.path.join(RES, sub, f"direct_{ab}.h5")
            if os.path.exists(p):
                runs[(label, ab)] = load(p)
                stats[(label, ab)] = file_stats(runs[(label, ab)], a.start)
        if (label, "a") in runs and (label, "b") in runs:
            pairs[label] = pair_stats(runs[(label, "a")], runs[(label, "b")], a.start)
            jumps[label] = jump_study(runs[(label, "a")], runs[(label, "b")], a.start)
    L = ["# Slope noise of the CPI burst, from the direct ensembles", "",
         "    /usr/bin/python3 bench/slope_noise.py --out " + os.path.relpath(a.out, os.path.join(HERE, "..")), "",
         f"Files (first {a.start:g} time units skipped; windows (start + kW, start + (k+1)W], non-overlapping):", ""]
    L += [f"* {k[0]} {k[1]}: `{r['path']}`, R = {r['R']}" for k, r in runs.items()]
    L += ["", "Slopes in d_p per time unit. SE = std_r(s)/sqrt(R) of the members' own least-squares slopes.", "",
          "## 1. Window scaling of SE", "",
          "RMS over nodes and windows of SE(W); a = exponent of Var(SE) ~ W^-a between successive W "
          "(white noise 3, random walk 1); 'fit' over all four W.", "",
          "| file | windows @W=5/10/20/40 | SE(5) | SE(10) | SE(20) | SE(40) | a 5-10 | a 10-20 | a 20-40 | a fit "
          "| Var(SE20)/Var(SE10) |", "|---" * 11 + "|"]
    for k, s in stats.items():
        L.append(f"| {k[0]} {k[1]} | {'/'.join(str(s['K'][w]) for w in WS)} | "
                 + " | ".join(f"{np.sqrt(s['se'][w]):.4f}" for w in WS) + " | "
                 + " | ".join(f"{s['a'][p]:.2f}" for p in zip(WS, WS[1:])) + f" | {s['a_fit']:.2f} | "
                 f"{s['se'][20] / s['se'][10]:.3f} |")
    L += ["", "Check of SE across the independent pair: RMS SE (a, b pooled) vs the measured noise of the "
          "ensemble-mean slope RMS(s_a - s_b)/sqrt(2) (ratio ~1 if SE is right).", "",
          "| case | W | RMS SE | RMS(s_a-s_b)/sqrt2 | ratio |", "|---|---|---|---|---|"]
    for lab, P in pairs.items():
        L += [f"| {lab} | {w} | {P[w][0]:.4f} | {P[w][1]:.4f} | {P[w][1] / P[w][0]:.2f} |" for w in WS]
    L += ["", "## 2. Correlation of the members' slope deviations across windows", "",
          "d(k) = s(k) - mean_r s(k); correlation of d(k) with d(k+lag), pooled over members, nodes, k. "
          "'pool m' = Var(mean of m successive d)/Var(d), which is 1/m (0.5, 0.25) for independent windows.", "",
          "| file | W | lag 1 | lag 2 | lag 3 | pool 2 (1/m = 0.5) | pool 4 (0.25) |", "|---" * 7 + "|"]
    for k, s in stats.items():
        for W in (10, 20):
            c, pf = s[("corr", W)], s[("pool", W)]
            L.append(f"| {k[0]} {k[1]} | {W} | {c[0]:+.2f} | {c[1]:+.2f} | {c[2]:+.2f} | {pf[0]:.3f} | {pf[1]:.3f} |")
    L += ["", "## 3. Coordinates with less slope noise (W = 10)", "",
          "Share of the members' deviation variance (sum over nodes of Var_r(s), averaged over windows) "
          "removed, relative to the raw ICDF. a: ICDF - own whole-bed centre of mass (com); b: ICDF - "
          "mean over nodes (diagnostic: the uniform-shift part); beta: ICDF - beta_i com with the best "
          "per-node beta_i (fitted to the same data: an upper bound for any com correction); PC k: share "
          "in the first k principal components of the 19 x 19 deviation covariance (in-sample); PC1(other): "
          "share along the *other* file's PC1 (out-of-sample). cos = |PC1 . uniform| (1 = pure shift). "
          "Whole-bed ranks (the ICDF of the light species within the whole bed's height distribution) "
          "need each member's whole-bed profile, which these files do not store: section 6 measures "
          "them on runs made with observe.bed = true.", "",
          "end: the slope (last - first sample)/W instead of least squares (the better estimator of a "
          "random walk's drift, by 1.2x in variance; worse for white noise).", "",
          "| file | RMS dev/node | a: -com | b: -node mean | beta·com | PC1 | PC1-2 | PC1-3 | PC1(other) | cos "
          "| beta range | com slope RMS | com SE RMS | end |", "|---" * 14 + "|"]
    for k, s in stats.items():
        other = stats.get((k[0], "b" if k[1] == "a" else "a"))
        po = ms(s["D"] @ other["pc1"]) / (np.sum(s["D"] ** 2) / len(s["D"])) if other else np.nan
        cs = np.cumsum(s["pc_share"])
        L.append(f"| {k[0]} {k[1]} | {np.sqrt(s['vraw'] / 19):.4f} | {s['rm_com']:.0%} | {s['rm_nodemean']:.0%} | "
                 f"{s['rm_beta']:.0%} | {cs[0]:.0%} | {cs[1]:.0%} | {cs[2]:.0%} | {po:.0%} | "
                 f"{s['pc1_cos_uniform']:.2f} | {s['beta'].min():.2f}..{s['beta'].max():.2f} | "
                 f"{np.sqrt(s['com_sig']):.4f} | {np.sqrt(s['com_se']):.4f} | {s['rm_end']:.0%} |")
    L += ["", "PC1 eigenvectors (sign: positive sum; uniform = 0.229 each), nodes p = 0.05..0.95:", ""]
    L += [f"* {k[0]} {k[1]}: " + " ".join(f"{v:+.2f}" for v in s["pc1"]) for k, s in stats.items()]
    L += ["", "## 4. Slope against its noise", "",
          "RMS over nodes and windows of the ensemble-mean slope (includes its noise), RMS SE, and the "
          "signal sqrt(MS(mean) - MS(SE)); per pair also the noise-free signal sqrt(mean s_a*s_b).", "",
          "| file | W | RMS mean slope | RMS SE | ratio | signal | signal/SE |", "|---" * 7 + "|"]
    for k, s in stats.items():
        for W in WS:
            sig = np.sqrt(max(0.0, s["sig"][W] - s["se"][W]))
            L.append(f"| {k[0]} {k[1]} | {W} | {np.sqrt(s['sig'][W]):.4f} | {np.sqrt(s['se'][W]):.4f} | "
                     f"{np.sqrt(s['sig'][W] / s['se'][W]):.2f} | {sig:.4f} | {sig / np.sqrt(s['se'][W]):.2f} |")
    L += ["", "| case | W | signal sqrt(mean s_a s_b) | noise RMS(s_a-s_b)/sqrt2 | signal/noise |", "|---" * 5 + "|"]
    for lab, P in pairs.items():
        L += [f"| {lab} | {w} | {P[w][2]:.4f} | {P[w][1]:.4f} | {P[w][2] / P[w][1]:.2f} |" for w in WS]
    L += ["", "## 5. Emulated jump (W = 10)", "",
          "Prediction X(t_k) + DT * (mean of the last m window slopes), X the ensemble-mean ICDF, t_k the "
          "window ends (the same t_k for all m). All columns RMS over nodes and t_k, d_p; both directions "
          "(a predicts, b predicts) pooled. same: vs the same ensemble's realised change; cross: vs the "
          "other ensemble's; eta: the realised change's own noise, sqrt(MS(dX_a - dX_b)/2), with "
          "'eta ref' = sqrt(2 mean Var_r(X)/R) its value if the members' offsets decorrelate over DT; "
          "true err: sqrt(cross^2 - eta^2) = error against the true mean change; DT*noise: measured "
          "noise of the (pooled) slope times DT, from s_a - s_b; DT*SE/sqrt(m): what SE predicts; "
          "bias: sqrt(true err^2 - (DT*noise)^2), lag/curvature error (negative: within the noise); "
          "rw: DT*noise if X's noise were a random walk with the measured eta^2 = q DT, i.e. "
          "DT*sqrt(1.2 q/(W m)).", "",
          "| case | DT | m | t_k | same | cross | eta | eta ref | true err | DT*noise | DT*SE/sqrt(m) | rw | bias |",
          "|---" * 13 + "|"]
    for lab, rows in jumps.items():
        L += [f"| {lab} | {r['DT']} | {r['m']} | {r['n']} | {rt(r['same'])} | {rt(r['cross'])} | "
              f"{rt(r['eta'])} | "
              f"{rt(r['ref'])} | {rt(r['corr'])} | {rt(r['noise'])} | {rt(r['pred'])} | {rt(r['rw'])} | "
              f"{rt(r['bias'])} |" for r in rows]
    L += ["", "## 6. Ranks in the whole bed", "",
          "Each light quantile height q_i as its rank among all particles of the same member, r_i = F_bed(q_i), "
          "F_bed the member's cumulative solid-fraction profile (`bed/solid_fraction`, observe.bed = true; each "
          "slab's volume spread uniformly over it): a uniform shift or expansion of the whole bed cancels. Members' "
          "least-squares slopes per window as above. Var = sum over nodes of Var_r(s), averaged over windows; "
          "'ranks [d_p]' = rank slopes divided by f_bed = dF_bed/dz at the window's ensemble-mean q_i (the "
          "window's mean density profile), so 'removed' = 1 - Var(ranks [d_p]) / Var(heights) compares in one "
          "unit. uniform = share of that coordinate's Var removed by subtracting the node mean (section 3b's "
          "measure: " + ", ".join(f"{k[0]} {k[1]} {s['rm_nodemean']:.0%}" for k, s in stats.items()
                                   if k[0].startswith("demo U0.19")) + "); ranks remove the uniform "
          "shift if it is ~0 in ranks. S/N = RMS ensemble-mean slope / RMS SE (unit-free; the mean slope "
          "includes its noise).", ""]
    bed = {}
    for p in a.bed_files:
        r = load_bed(p) if os.path.exists(p) else None
        name = os.path.relpath(p, os.path.join(HERE, "..")) if os.path.abspath(p).startswith(RES) else p
        if r is None:
            L.append(f"* `{name}`: " + ("no bed/solid_fraction, skipped" if os.path.exists(p) else "missing"))
            continue
        bed[name] = bed_stats(r, a.start)
        L.append(f"* `{name}`: U_s = {r['U']}, bed.count = {r['N']}, R = {r['R']}, {r['T']:g} time units"
                 + ("" if os.path.abspath(p).startswith(RES) else " -- **not a study file: a test file (e.g. the "
                    "tiny bed of tests/scripts/tiny_scene.cfg) for testing the method only, not a result**"))
    if not a.bed_files:
        L.append("* none given (the default, `bench/results/slope_study_r4_u0.19_t600/direct_b.h5` and `direct_c.h5`, "
                 "not written yet)")
    L += ["", "| file | W | windows | Var heights | Var ranks | Var ranks [d_p] | removed | uniform heights "
          "| uniform ranks | S/N heights | S/N ranks | S/N ranks [d_p] |", "|---" * 12 + "|"]
    for name, B in bed.items():
        L += [f"| `{os.path.basename(name)}` | {W} | {b['K']} | {b['vh']:.3g} | {b['vr']:.3g} | {b['vrh']:.3g} | "
              f"{1 - b['vrh'] / b['vh']:.0%} | {b['uh']:.0%} | {b['ur']:.0%} | {b['sh']:.2f} | {b['sr']:.2f} | "
              f"{b['srh']:.2f} |" for W, b in B.items()]
    L += ["", "Per node (W = 10), p = 0.05..0.95: share removed 1 - Var_r(rank slope [d_p]) / Var_r(height slope), "
          "and the mean f_bed [1/d_p]:", ""]
    for name, B in bed.items():
        if 10 in B:
            L += [f"* `{os.path.basename(name)}` removed: " + " ".join(f"{v:+.0%}" for v in B[10]["node"]),
                  f"* `{os.path.basename(name)}` f_bed: " + " ".join(f"{v:.3f}" for v in B[10]["f"])]
    with open(os.path.join(a.out, "slope_noise.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
    for k, s in stats.items():
        ax[0].loglog(WS, [np.sqrt(s["se"][w]) for w in WS], "o-", label=f"{k[0]} {k[1]}")
        ax[1].semilogy(np.arange(1, 20), s["pc_share"], "o-", ms=3, label=f"{k[0]} {k[1]}")
        ax[2].plot(np.linspace(0.05, 0.95, 19), s["pc1"], "o-", ms=3, label=f"{k[0]} {k[1]}")
    w = np.array(WS, float)
    ax[0].loglog(w, 0.02 * (w / 10) ** -1.5, "k--", label="W^-1.5 (white)")
    ax[0].loglog(w, 0.02 * (w / 10) ** -0.5, "k:", label="W^-0.5 (random walk)")
    ax[0].set(xlabel="window W", ylabel="RMS SE [d_p / t.u.]", title="1. SE vs window", xticks=WS, xticklabels=WS)
    ax[0].minorticks_off()
    ax[1].set(xlabel="component", ylabel="share of deviation variance", title="3c. PCA spectrum (W = 10)")
    ax[2].axhline(1 / np.sqrt(19), color="k", ls=":", label="uniform shift")
    ax[2].set(xlabel="p", ylabel="PC1 component", title="3c. first eigenvector")
    for x in ax:
        x.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "slope_noise.png"), dpi=110)
    print(f"wrote {a.out}/slope_noise.md, slope_noise.png")


if __name__ == "__main__":
    main()

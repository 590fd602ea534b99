#!/usr/bin/python3
"""Plots a per-run error CSV of vimot-vio-eval / vimot-log-eval: position
and orientation error per axis against time with the filter's +-3 sigma
bounds (as Fig. 1 of Eckenhoff et al., Schmidt-EKF-based visual-inertial
moving object tracking), to a PNG.

CSV columns (docs/evaluation.md): t, err_px, err_py, err_pz [m],
err_rx, err_ry, err_rz [deg], sig3_px, sig3_py, sig3_pz [m],
sig3_rx, sig3_ry, sig3_rz [deg], nees_p, nees_r.
Position errors are in G (x, y, z); orientation errors in the IMU frame I.

Uses Debian's python3-matplotlib and python3-numpy (scripts/install_deps.sh).
"""
import argparse
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ["t", "err_px", "err_py", "err_pz", "err_rx", "err_ry", "err_rz",
           "sig3_px", "sig3_py", "sig3_pz", "sig3_rx", "sig3_ry", "sig3_rz", "nees_p", "nees_r"]


def load(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        sys.exit(f"plot_errors: {path}: missing columns {missing} (is it a vimot error CSV?)")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[0] == 0:
        sys.exit(f"plot_errors: {path}: no rows")
    return {name: data[:, header.index(name)] for name in COLUMNS}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv", help="per-run error CSV (e.g. out/seed001_errors.csv)")
    ap.add_argument("-o", "--output", help="PNG to write (default: the CSV name with .png)")
    ap.add_argument("--title", default=None, help="figure title (default: the CSV name)")
    ap.add_argument("--dpi", type=int, default=120)
    args = ap.parse_args()

    d = load(args.csv)
    t = d["t"] - d["t"][0]
    out = args.output or (args.csv[:-4] if args.csv.endswith(".csv") else args.csv) + ".png"

    fig, axes = plt.subplots(3, 2, sharex=True, figsize=(11, 7.5))
    rows = [("x", "px", "rx"), ("y", "py", "ry"), ("z", "pz", "rz")]
    for i, (axis, p, r) in enumerate(rows):
        for j, (key, unit, frame) in enumerate([(p, "m", "G"), (r, "deg", "I")]):
            ax = axes[i, j]
            ax.plot(t, d["err_" + key], color="tab:blue", lw=0.9, label="error")
            ax.plot(t, d["sig3_" + key], color="tab:red", lw=0.9, ls="--", label="±3σ")
            ax.plot(t, -d["sig3_" + key], color="tab:red", lw=0.9, ls="--")
            ax.axhline(0.0, color="0.6", lw=0.5)
            what = "position" if j == 0 else "orientation"
            ax.set_ylabel(f"{what} {axis} [{unit}]")
            ax.grid(True, lw=0.3)
            if i == 0:
                ax.set_title(f"{what} error ({frame} frame)")
    axes[0, 0].legend(loc="upper left", fontsize=8)
    for ax in axes[2]:
        ax.set_xlabel("time [s]")

    rmse_p = np.sqrt(np.mean(d["err_px"] ** 2 + d["err_py"] ** 2 + d["err_pz"] ** 2))
    rmse_r = np.sqrt(np.mean(d["err_rx"] ** 2 + d["err_ry"] ** 2 + d["err_rz"] ** 2))
    title = args.title or args.csv
    fig.suptitle(f"{title}\nRMSE {rmse_p:.3f} m / {rmse_r:.3f}°, NEES position {np.mean(d['nees_p']):.2f}, "
                 f"orientation {np.mean(d['nees_r']):.2f} (ideal 3), {len(t)} samples", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=args.dpi)
    print(out)


if __name__ == "__main__":
    main()

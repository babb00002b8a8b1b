#!/usr/bin/python3
"""Simulate a test, calibrate it, print the coefficients and plot the positions' residuals (docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/calibrate_simulated.py [--config scenario.toml] [--seed 1]
                                                                             [--plot residuals.png]

The plot needs matplotlib (Debian's python3-matplotlib); without it the script prints the residuals instead.
"""

import argparse

import gyrocal


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", help="configuration file (TOML); default: the built-in scenario")
    parser.add_argument("--seed", type=int, default=1, help="the noise's seed (default: 1)")
    parser.add_argument("--plot", default="residuals.png", help="where to save the plot (default: residuals.png)")
    args = parser.parse_args()

    sc = gyrocal.Scenario.load(args.config) if args.config else gyrocal.Scenario()
    rec = gyrocal.simulate(sc, seed=args.seed)
    print(f"simulated {rec['time_s'].size} samples over {rec['time_s'][-1]:.1f} s")

    res = gyrocal.calibrate(rec, sc, method="least-squares", compensation="full", estimate=[])
    print(f"{'coefficient':<12}{'estimate':>14}{'std':>12}  unit")
    for name, c in res["coefficients"].items():
        if c["identifiable"]:
            print(f"{name:<12}{c['value']:>14.6g}{c['std']:>12.3g}  {c['unit']}")
        else:
            print(f"{name:<12}{'not identifiable':>26}  {c['unit']}")
    for c in res["combinations"]:  # what the plan does identify where single coefficients are not
        print(f"{c['name']:<12}{c['value']:>14.6g}{c['std']:>12.3g}  {c['unit']}")
    for w in res["warnings"]:
        print("warning:", w)

    positions = res["positions"]
    labels = [str(p.get("index", i + 1)) for i, p in enumerate(positions)]
    residuals = [p.get("residual_deg_h") for p in positions]
    errors = [p.get("std_err_deg_h") for p in positions]
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (Debian: python3-matplotlib); the residuals, deg/h:")
        for label, r in zip(labels, residuals):
            print(f"  position {label}: {r}")
        return

    fig, ax = plt.subplots(figsize=(8, 4))
    ax.errorbar(range(len(residuals)), residuals, yerr=errors, fmt="o", capsize=3)
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set_xticks(range(len(labels)), labels)
    ax.set_xlabel("position")
    ax.set_ylabel("residual (measured - model), deg/h")
    ax.set_title(f"least squares, seed {args.seed}: residuals with their standard errors")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()

"""Benchmark: flag flutter in a steady wind; writes DIR/bench_flutter.json.

Each material of the flags scene (cotton, nylon, canvas) alone in a steady uniform 8 m/s
wind along it, seeded by the scene's 2 mm ripple, 6 s: the dominant frequency and the
amplitude (half peak-to-peak) of the free edge's lateral motion after 2 s, the reduced
frequency f L / U and the phase speed of the waves along it, for every integrator (implicit is
BDF2, the scene's default; backward Euler and a flat flag are the diagnosis of the old
boards). The literature beside it (docs/cloth.md): waves travel root to tip at close to the
wind's speed with a wavelength of about 1.87 L (Raynaud & Mulleners 2026; Alben 2022 for the
speed), so f L / U is about 0.53 times c / U.
Run: ``.venv/bin/python benchmarks/bench_flutter.py --out out/bench [--quick]``.
"""
from __future__ import annotations

from common import machine, parse_args, write_json  # noqa: I001 (pins threads first)

import time  # noqa: E402
from dataclasses import replace  # noqa: E402

from interplay.scenes import flags as F  # noqa: E402

LITERATURE = {"wavelength_over_length": 1.87, "wave_speed_over_wind": 1.0,
              "reduced_frequency": 0.53,
              "sources": ["G. Raynaud, K. Mulleners, On the wake and flapping dynamics of "
                          "different aspect ratio flags, arXiv:2602.06237 (2026)",
                          "S. Alben, Dynamics of flags over wide ranges of mass and bending "
                          "stiffness, arXiv:2106.14988"]}


def main():
    args, _ = parse_args(__doc__)
    duration = 3.0 if args.quick else 6.0
    settle = 1.0 if args.quick else 2.0
    speed = 8.0
    cases = [("implicit (BDF2)", {}, {}), ("implicit (backward Euler)", {}, {"scheme": "theta"}),
             ("flat (no ripple)", {}, {"ripple": 0.0})]
    if not args.quick:
        cases += [("explicit", {"integrator": "explicit", "dt": 8e-5}, {}),
                  ("localglobal", {"integrator": "localglobal"}, {})]
    rows = []
    for material in ("cotton", "nylon", "canvas"):
        base = getattr(F.FlagsParams(), material)
        for label, over, kw in cases:
            t0 = time.perf_counter()
            r = F.flutter_trial(replace(base, **over), speed, duration, settle, **kw)
            r.update(material=material, integrator=label, wall_s=time.perf_counter() - t0,
                     density_kg_m2=base.density, mass_ratio=base.density / (1.2 * base.width))
            rows.append(r)
            print(f"{material:7s} {label:26s} f {r['frequency_hz']:5.2f} Hz  "
                  f"A {r['amplitude_m']:.3f} m (A/L {r['amplitude_over_length']:.3f})  fL/U {r['reduced_frequency']:.2f}"
                  f"  c {r['wave_speed_m_s']:.2f} m/s  [{r['wall_s']:.1f} s]", flush=True)
    out = write_json(args.out, "bench_flutter.json", {
        "what": f"free-edge flutter in a steady {speed} m/s wind, {duration} s, after {settle} s",
        "machine": machine(), "literature": LITERATURE, "rows": rows})
    print(f"wrote {out}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""How far the catalogue's dead-time form (a linear band, v_err*clamp(i/band)) is from a smooth one
(A*tanh(i/i_band), the independent generator's), as the dq currents see it, and how much of the
difference a stator resistance can take (docs/diagnose.md, "Tests on independent data", seed 41).

The dq frame sees each leg error's fundamental: for a phase current of amplitude I,
F(I) = (2/pi) * integral_0^pi e(I*sin(th))*sin(th) dth. The linear band's v_err and band are fitted to
the tanh's F over the amplitudes a log spans (least squares); then a resistance term dR*I is freed too.
"""
import argparse
import math


def fundamental(e, amplitude, n=400):
    return 2.0 / n * sum(e(amplitude * math.sin((k + 0.5) * math.pi / n)) * math.sin((k + 0.5) * math.pi / n)
                         for k in range(n))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--amplitude-V", type=float, default=10.18, help="tanh form's amplitude A [V]")
    ap.add_argument("--band-A", type=float, default=0.03 * 4.93 * math.sqrt(2), help="tanh form's i_band [A]")
    ap.add_argument("--max-current-A", type=float, default=7.0, help="largest phase-current amplitude [A]")
    ap.add_argument("--r-s-Ohm", type=float, default=2.25, help="R_s to express the resistance share in")
    a = ap.parse_args()
    amplitudes = [0.1 + (a.max_current_A - 0.1) * k / 139 for k in range(140)]
    target = [fundamental(lambda i: a.amplitude_V * math.tanh(i / a.band_A), x) for x in amplitudes]
    best = None
    for j in range(5, 81):
        band = a.band_A * j / 20
        f = [fundamental(lambda i, b=band: max(-1.0, min(1.0, i / b)), x) for x in amplitudes]
        s11 = sum(v * v for v in f)
        s12 = sum(v * x for v, x in zip(f, amplitudes))
        s22 = sum(x * x for x in amplitudes)
        y1 = sum(v * y for v, y in zip(f, target))
        y2 = sum(x * y for x, y in zip(amplitudes, target))
        v_only = y1 / s11
        rms_only = math.sqrt(sum((y - v_only * v) ** 2 for y, v in zip(target, f)) / len(f))
        det = s11 * s22 - s12 * s12
        v, d_r = (y1 * s22 - y2 * s12) / det, (s11 * y2 - s12 * y1) / det
        rms = math.sqrt(sum((y - v * g - d_r * x) ** 2 for y, g, x in zip(target, f, amplitudes)) / len(f))
        if best is None or rms_only < best[0]:
            best = (rms_only, band, v_only, d_r, rms)
    rms_only, band, v_only, d_r, rms = best
    print(f"linear band fitted to tanh: band {band:.3f} A ({band / a.band_A:.2f} i_band), v_err {v_only:.3f} V, "
          f"fundamental mismatch {rms_only:.3f} V RMS")
    print(f"with a resistance freed too: dR {d_r:+.4f} Ohm ({100 * d_r / a.r_s_Ohm:+.2f} % of R_s), {rms:.3f} V RMS")


if __name__ == "__main__":
    main()

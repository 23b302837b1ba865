"""Regenerate the synthetic sine records in this directory.

System: G(s) = 1 / (1 + s**0.5), excited at five frequencies with u(t) = sin(omega t). Every
record holds three repeated series with Gaussian noise (standard deviation 0.01 on input and
output), an offset and a slow linear drift on the output, and 6.6 periods, so that the
extraction has to cut to whole periods and remove offset and trend (thesis §4.3.1).

Run ``python make_records.py`` in this directory; the output is deterministic.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

OMEGAS = (0.1, 0.3, 1.0, 3.0, 10.0)
SAMPLES_PER_PERIOD = 32
PERIODS = 6.6
N_SERIES = 3
NOISE = 0.01


def g_true(omega):
    return 1.0 / (1.0 + (1j * omega) ** 0.5)


def main(seed: int = 20240611) -> None:
    rng = np.random.default_rng(seed)
    here = Path(__file__).resolve().parent
    for omega in OMEGAS:
        dt = 2 * np.pi / omega / SAMPLES_PER_PERIOD
        t = np.arange(int(SAMPLES_PER_PERIOD * PERIODS)) * dt
        g = g_true(omega)
        lines = [
            "# synthetic sine record: G(s) = 1/(1 + s^0.5), 3 series, noise sd 0.01",
            f"# G(j omega) = {g.real:.12g} {g.imag:+.12g}j",
        ]
        if omega == 1.0:
            lines.append(f"# freq: {omega / (2 * np.pi)!r} Hz")
        else:
            lines.append(f"# omega: {omega!r} rad/s")
        lines.append("series,time,input,output")
        for s in range(1, N_SERIES + 1):
            u = np.sin(omega * t) + NOISE * rng.standard_normal(t.size)
            y = abs(g) * np.sin(omega * t + np.angle(g)) + 0.05 + 0.002 * omega * t
            y = y + NOISE * rng.standard_normal(t.size)
            lines += [f"{s},{tk:.8g},{uk:.6g},{yk:.6g}" for tk, uk, yk in zip(t, u, y)]
        name = f"sine_omega_{omega:g}".replace(".", "p") + ".csv"
        (here / name).write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()

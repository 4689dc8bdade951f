"""
Four quasi-zero-stiffness mechanisms on the paper's rig
=======================================================

The same payload (6.4 kg), guide friction, stops and PI + damping loop, with four springs
(docs/model.md §3.1): the MagSpring's ``-a tanh(b z)`` (the paper's), the three-spring
mechanism of Carrella, Brennan & Waters at its quasi-zero condition
(:meth:`qzs.ObliqueSpringQZS.quasi_zero`), a hardening Duffing spring
(:class:`qzs.PolynomialSpring`, 100 N/m and 5e4 N/m^3 about the operating point) and a
measured curve (:class:`qzs.TabulatedSpring`: the MagSpring sampled every 5 mm with a 0.05 N
ripple of 20 mm pitch, as a rig's force-displacement test may show). Top: the static force
against the payload's weight and the tangent stiffness around the operating point. Bottom:
the transmissibility of a 0-20 Hz chirp (10 mm) with the guide's stick-slip friction (solid)
and without it (dashed, the same viscous damping), and what stiction costs each mechanism:
the rise of the RMS transmissibility over 0.5-3 Hz (the softest springs lose most: stiction
locks the payload below about 2 Hz whatever holds it, and takes away what the quasi-zero
stiffness would have given), with each spring's quasi-zero stroke (the
span around the setpoint, inside the stops, where its stiffness stays below that of a 1 Hz
spring for the payload, m (2 pi 1 Hz)^2 = 253 N/m).
"""
import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import qzs

RIG = qzs.IsolatorParameters()
SETPOINT = qzs.ControllerParameters().position_setpoint  # -0.060 m
WEIGHT = RIG.mass * RIG.gravity
positions = np.arange(-0.16, 0.0401, 0.005)
ripple = 0.05 * np.sin(2 * np.pi * positions / 0.020)
magspring = qzs.TanhSpring(plateau=RIG.spring_force, shape=RIG.spring_shape)
SPRINGS = {
    "MagSpring (tanh)": magspring,
    "three-spring QZS": qzs.ObliqueSpringQZS.quasi_zero(),
    "Duffing (cubic)": qzs.PolynomialSpring(coefficients=(WEIGHT, -100.0, 0.0, -5e4),
                                            center=SETPOINT),
    "measured curve (table)": qzs.TabulatedSpring(positions=positions,
                                                  forces=magspring.force(positions) + ripple,
                                                  outside="extend"),
}
COLORS = dict(zip(SPRINGS, ("C0", "C1", "C2", "C3")))
CHIRP = qzs.Chirp(amplitude=0.010, f1=20.0, duration=240.0)
BAND = (0.5, 3.0)  # [Hz] where stiction shows (the paper's Fig. 7)
SOFT = RIG.mass * (2 * np.pi * 1.0) ** 2  # [N/m] stiffness of a 1 Hz spring for the payload


def quasi_zero_stroke(law):
    """Span [m] around the setpoint, inside the stops, where the stiffness is below SOFT."""
    z = np.linspace(SETPOINT - RIG.stroke_half, SETPOINT + RIG.stroke_half, 16001)
    soft = law.stiffness(z) < SOFT
    middle = z.size // 2
    low = middle - np.argmin(soft[middle::-1]) if not soft[middle::-1].all() else 0
    high = middle + np.argmin(soft[middle:]) if not soft[middle:].all() else z.size
    return z[high - 1] - z[low]


def transmissibility(run):
    """Welch estimate of the payload's over the base's acceleration (8192-point segments)."""
    return qzs.transmissibility(run.base_acceleration, run.payload_acceleration, 1000.0,
                                fft_length=8192)


runs = {}
for name, law in SPRINGS.items():
    for friction in (True, False):
        iso = dataclasses.replace(RIG, spring=law, **({} if friction else dict(
            stiction_force=0.0, coulomb_force=0.0)))
        runs[name, friction] = qzs.simulate(CHIRP, iso, dt=1e-4, sample_rate=1000.0)

fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), constrained_layout=True)
z = np.linspace(-0.14, 0.02, 801)
ax = axes[0, 0]
for name, law in SPRINGS.items():
    ax.plot(1e3 * z, law.force(z), color=COLORS[name], label=name)
ax.axhline(WEIGHT, color="k", lw=0.8, ls=":", label=f"payload weight {WEIGHT:.2f} N")
ax.axvline(1e3 * SETPOINT, color="0.6", lw=0.8)
ax.set(xlabel="relative position z [mm]", ylabel="spring force on the payload [N]",
       title="static force", ylim=(40.0, 80.0))
ax.legend(fontsize=8)
ax = axes[0, 1]
near = np.linspace(SETPOINT - 0.03, SETPOINT + 0.03, 601)
for name, law in SPRINGS.items():
    ax.plot(1e3 * near, law.stiffness(near), color=COLORS[name], label=name)
ax.axvline(1e3 * SETPOINT, color="0.6", lw=0.8)
ax.set(xlabel="relative position z [mm]", ylabel="tangent stiffness -dF/dz [N/m]",
       title=f"stiffness within ±30 mm of the setpoint ({1e3 * SETPOINT:g} mm)",
       ylim=(-30.0, 260.0))
ax = axes[1, 0]
penalty, stroke = {}, {}
for name in SPRINGS:
    rms = {}
    for friction, style in ((True, "-"), (False, "--")):
        estimate = transmissibility(runs[name, friction])
        keep = estimate.trusted & (estimate.frequency > 0.2)
        ax.plot(estimate.frequency[keep], 20 * np.log10(estimate.magnitude[keep]), style,
                color=COLORS[name], lw=1.0 if friction else 0.8,
                label=name if friction else None)
        band = keep & (estimate.frequency >= BAND[0]) & (estimate.frequency <= BAND[1])
        rms[friction] = float(np.sqrt(np.mean(estimate.magnitude[band] ** 2)))
    penalty[name] = rms[True] - rms[False]
    stroke[name] = 1e3 * quasi_zero_stroke(SPRINGS[name])
ax.set(xscale="log", xlim=(0.2, 20.0), xlabel="frequency [Hz]",
       ylabel="transmissibility |T| [dB]",
       title="chirp 0-20 Hz, 10 mm: friction (solid), none (dashed)")
ax.axhline(0.0, color="k", lw=0.6)
ax.legend(fontsize=8)
ax = axes[1, 1]
names = list(SPRINGS)
bars = ax.bar(range(len(names)), [penalty[n] for n in names],
              color=[COLORS[n] for n in names])
for bar, name in zip(bars, names):
    ax.annotate(f"quasi-zero stroke\n{stroke[name]:.0f} mm", (bar.get_x() + bar.get_width() / 2,
                                                  bar.get_height()),
                ha="center", va="bottom", fontsize=8)
ax.set_xticks(range(len(names)), [n.replace(" (", "\n(") for n in names], fontsize=8)
ax.set_ylim(0.0, 1.3 * max(penalty.values()))
ax.set(ylabel=f"RMS |T| over {BAND[0]:g}-{BAND[1]:g} Hz: with less without stiction [-]",
       title="what stiction costs each mechanism")
fig.suptitle("Four QZS mechanisms on the paper's rig (6.4 kg, its friction and PI loop)")

for name in names:
    print(f"{name:24s} stiction raises RMS |T| over {BAND[0]:g}-{BAND[1]:g} Hz by "
          f"{penalty[name]:.3f}; quasi-zero stroke {stroke[name]:.0f} mm")

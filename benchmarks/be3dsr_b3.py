"""BE3DSR on B3: its cost per step against BE3D (interleaved), and the long runs of issue 20's done criterion.

``python -m benchmarks.be3dsr_b3 cost [--elements 8] [--t-end 0.3] [--repeats 5]`` runs B3 (revision 2,
Lobatto IIIA-3, h = 1e-3, modified Newton tol 1e-8) with BE3D (the chapter's update after every step) and
BE3DSR (its default ``update_below=0.5``) alternating over ``[0, t_end]`` and prints the median CPU time per
step of each, their ratio and the residual evaluations per step. JIT compilation happens in an untimed
warm-up; nothing is asserted.

``python -m benchmarks.be3dsr_b3 long --elements N [--t-end 50] [--segment 2.5] [--h 1e-3] [--tol 1e-8]
[--element BE3DSR] [--method lobatto3] [--out FILE] [--log FILE]`` integrates the element (default BE3DSR)
with N elements to ``t_end`` in segments (each restarts from the last state and director state, as the
driver does after a director update) and prints, after each segment, the time reached, the CPU time so far,
``E = T + U - W_ext`` (the energy balance: the beam starts at rest and unstrained), the largest deviation
``|E - E(t_load)|`` after the load within the segment and up to it (the done criterion: constant to 1e-6 J)
and the director updates so far. A failing segment prints its time and reason and ends the run. ``--tol``
is modified Newton's relative tolerance (energy-momentum keeps its round-off default unless given);
``--log``: the same lines appended to a text file and flushed, so a stopped run still reports; ``--out``:
an ``.npz`` with the output times, ``T + U``, ``E`` and the position of B, rewritten after every segment.
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from ancfdae import EnergyMonitor, PointSensor, simulate
from ancfdae.integrators import NewtonOptions
from ancfdae.studies._flying import OWN_NEWTON, T_HAT, b3_beam, output_times, simulate_case

H = 1e-3
NEWTON = dict(tol=1e-8, jacobian="modified")


def cost(n: int, t_end: float, repeats: int) -> None:
    """Median CPU per step of BE3D and BE3DSR over ``[0, t_end]``, interleaved."""
    beams = {name: b3_beam(name, n) for name in ("BE3D", "BE3DSR")}
    for beam in beams.values():                       # warm-up: compiles or loads the JIT cache
        simulate_case(beam, 0.01, h=H, energy=False)
    cpu = {k: [] for k in beams}
    evals = {}
    for _ in range(repeats):
        for name, beam in beams.items():
            rec = simulate_case(beam, t_end, h=H, energy=False)
            steps = rec["result"].stats["steps"]
            cpu[name].append(rec["cpu"] / steps)
            evals[name] = rec["result"].stats["residual_evals"] / steps
    med = {k: statistics.median(v) for k, v in cpu.items()}
    for name in beams:
        print(f"{name} {n} el, [0, {t_end:g}] s: CPU per step median {1e3 * med[name]:.3f} ms "
              f"(runs: {', '.join(f'{1e3 * x:.3f}' for x in cpu[name])}), residual evaluations per step "
              f"{evals[name]:.2f}")
    print(f"BE3DSR / BE3D per step: {med['BE3DSR'] / med['BE3D']:.2f}")


def long_run(n: int, t_end: float, segment: float, out: str | None, dt_out: float = 0.01, h: float = H,
             tol: float | None = None, element: str = "BE3DSR", method: str = "lobatto3",
             log_file: str | None = None) -> None:
    """``element`` on B3 to ``t_end`` in segments, with the energy after the load reported per segment."""
    beam = b3_beam(element, n)
    q, v = beam.initial_state()
    state = beam.event_state()
    t0, work, cpu, events = 0.0, 0.0, 0.0, 0
    ts, tu, es, tips = [], [], [], []
    e_load = None
    newton = {} if method in OWN_NEWTON and tol is None else {"newton": NewtonOptions(**(NEWTON | (
        {} if tol is None else {"tol": tol})))}
    name = f"{element} {n} el, {method}, h = {h:g}, tol {tol if tol is not None else 'default'}"

    def report(line: str) -> None:
        print(line, flush=True)
        if log_file:
            with open(log_file, "a") as f:
                f.write(line + "\n")

    report(f"{name}: B3 to {t_end:g} s in segments of {segment:g} s")
    while t0 < t_end - 1e-12:
        t1 = min(t0 + segment, t_end)
        t_eval = t0 + output_times(t1 - t0, dt_out)
        t_eval[-1] = t1
        c0 = time.process_time()
        res = simulate(beam, (t0, t1), method=method, h=h, t_eval=t_eval, q0=q, v0=v, state0=state,
                       monitors=[PointSensor(s=0.0, name="tip"), EnergyMonitor()], **newton)
        cpu += time.process_time() - c0
        events += int(res.stats.get("model_events", 0))
        log = res.monitors["energy"]
        kin_str = np.asarray(log["kinetic"]) + np.asarray(log["strain"])
        E = kin_str - (work + np.asarray(log["work"]))
        k = slice(1, None) if ts else slice(None)             # the segment's first output is the last one's
        n_before = len(ts)
        ts.extend(res.t[k]), tu.extend(kin_str[k]), es.extend(E[k])
        tips.extend(np.asarray(res.monitors["tip"]["position"]).reshape(res.t.size, -1)[k])
        t_arr, e_arr = np.asarray(ts), np.asarray(es)
        after = t_arr >= T_HAT - 1e-9
        if e_load is None and after.any():
            e_load = float(e_arr[np.argmax(after)])
        seg = np.zeros_like(after)
        seg[n_before:] = True
        if e_load is not None:
            dev = float(np.max(np.abs(e_arr[after] - e_load)))
            dev_seg = float(np.max(np.abs(e_arr[after & seg] - e_load))) if (after & seg).any() else float("nan")
        else:
            dev = dev_seg = float("nan")
        report(f"{name}: t = {t_arr[-1]:.3f} s, CPU {cpu:.0f} s ({cpu / max(t_arr[-1], 1e-300):.2f} s per "
               f"simulated s), E = {e_arr[-1]:.9e} J, max |E - E(t_load)| after the load: in "
               f"[{t0:g}, {t_arr[-1]:.3f}] {dev_seg:.2e} J, up to here {dev:.2e} J, director updates so far "
               f"{events}, status {res.status}")
        if out:
            np.savez(out, t=t_arr, kinetic_strain=np.asarray(tu), E=e_arr, tip=np.asarray(tips), cpu=cpu)
        if res.status != "success":
            report(f"{name} failed at t = {res.t_fail} s: {res.message}")
            return
        work += float(np.asarray(log["work"])[-1])
        t0 = t1
        q, v = res.q[-1], res.v[-1]
        state = {k: np.asarray(x)[-1] for k, x in res.model_state.items()} or state
    report(f"{name}: reached {t_end:g} s")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("mode", choices=("cost", "long"))
    p.add_argument("--elements", type=int, default=8)
    p.add_argument("--t-end", type=float, default=None)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--segment", type=float, default=2.5)
    p.add_argument("--out", default=None)
    p.add_argument("--log", default=None)
    p.add_argument("--h", type=float, default=H)
    p.add_argument("--tol", type=float, default=None)
    p.add_argument("--element", choices=("BE3DSR", "BE3D"), default="BE3DSR")
    p.add_argument("--method", default="lobatto3")
    a = p.parse_args()
    if a.mode == "cost":
        cost(a.elements, a.t_end or 0.3, a.repeats)
    else:
        long_run(a.elements, a.t_end or 50.0, a.segment, a.out, h=a.h, tol=a.tol, element=a.element,
                 method=a.method, log_file=a.log)


if __name__ == "__main__":
    main()

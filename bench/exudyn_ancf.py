#!/usr/bin/env python3
"""bench/exudyn_ancf.py — the paper's spin-up (Liu, Hong & Liu 2009, section 4.1) as an Exudyn ANCF
cable, for bench/exudyn_ancf.sh (issue 32 item 4: the exact beam against Exudyn 1.11's ANCF cable).

    python3 bench/exudyn_ancf.py --omega0 W --elements N --step H --out TIP.csv [--uf symbolic|python]
                                 [--t-end 20] [--solver dense|sparse]

The beam of scenes/exact/spinup_w15_exact.yaml (1.8 m, rho 2767 kg/m^3, A 2.5e-4 m^2, I 1.302e-10
m^4, E 68.95 GPa) as N ObjectANCFCable2D elements (Exudyn's planar geometrically exact cable: axial
strain and bending, full integration). Its root node is held at the origin by a GenericJoint to
a hub (a planar rigid body on a revolute joint to ground) whose angle follows the spin-up law of
Eq. 41 (joints/time_law.c's spinup: theta = omega0 (t^2/2 + (T/2 pi)^2 (cos(2 pi t/T) - 1)) / T up
to T = 15 s, then omega0 (t - T/2)) through a CoordinateConstraint's offset user function — as
Exudyn's own Examples/ANCFrotatingCable2D.py builds a rotating cable. The user function is a
symbolic one by default (evaluated in C++: Exudyn's fast path), or the plain Python one.
Integration: Exudyn's default implicit generalized-alpha with N steps of fixed size H (no step-size
control; Exudyn halves a step only when Newton fails), modified Newton with a Jacobian per step
and an absolute residual tolerance of 1e-6 (why: below), everything else Exudyn's defaults;
EigenSparse linear solves (at 16 elements 0.077 s against 0.100 s dense for 2 s of the run).

Writes TIP.csv with t, beam.tip_u, beam.tip_v: the tip's displacement in the hub frame (axial,
transverse), every 0.01 s (a sensor stored in memory), the columns flexmbd writes for the beam;
prints one line `cpu_s=... steps=... fast=0|1` (fast: Exudyn's fast module was used, bench/exudyn_ancf.sh's
head says how to build it): the process CPU time of mbs.Assemble() and
mbs.SolveDynamic() (the model built in Python and the import of exudyn not counted).
"""
import argparse
import math
import sys
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--omega0", type=float, required=True)
    ap.add_argument("--elements", type=int, required=True)
    ap.add_argument("--step", type=float, required=True)
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--out", required=True)
    ap.add_argument("--uf", choices=["symbolic", "python"], default="symbolic")
    ap.add_argument("--solver", choices=["dense", "sparse"], default="sparse")
    ap.add_argument("--newton", choices=["modified-jac", "modified", "full"], default="modified-jac")
    ap.add_argument("--abstol", type=float, default=1e-6)
    ap.add_argument("--verbose", type=int, default=0)
    ap.add_argument("--checked", action="store_true",
                    help="Exudyn's default module (range checks); without it the fast one when built")
    a = ap.parse_args()

    # Exudyn's fast track (exudynCPPfast: no range checks, "speedup may be 30% and more", its
    # __init__.py), opted into before the first import; Exudyn falls back to the checked module
    # when it is not built, and says which it loaded
    sys.exudynFast = not a.checked
    import exudyn as exu
    from exudyn.utilities import (Cable2D, CoordinateConstraint, GenerateStraightLineANCFCable2D, GenericJoint,
                                  InertiaCuboid, MarkerBodyRigid, MarkerNodeCoordinate, MarkerNodeRigid,
                                  NodePointGround, ObjectGround, RevoluteJoint2D, SensorNode)

    L, rho, A, I, E = 1.8, 2767.0, 2.5e-4, 1.302e-10, 68.95e9
    T, w0 = 15.0, a.omega0

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    cable = Cable2D(physicsMassPerLength=rho * A, physicsBendingStiffness=E * I, physicsAxialStiffness=E * A,
                    useReducedOrderIntegration=0)
    nodes = GenerateStraightLineANCFCable2D(mbs, [0, 0, 0], [L, 0, 0], a.elements, cable)[0]
    # the hub: its angle prescribed, so its inertia does not enter the beam's motion
    hub = mbs.CreateRigidBody(referencePosition=[0, 0, 0], inertia=InertiaCuboid(1000.0, [0.01, 0.01, 0.01]),
                              create2D=True, returnDict=True)
    m_root = mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[0]))
    m_hub = mbs.AddMarker(MarkerBodyRigid(bodyNumber=hub["bodyNumber"], localPosition=[0, 0, 0]))
    mbs.AddObject(GenericJoint(markerNumbers=[m_root, m_hub], constrainedAxes=[1, 1, 0, 0, 0, 1]))
    m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    mbs.AddObject(RevoluteJoint2D(markerNumbers=[m_hub, m_ground]))
    n_ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    mc_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
    mc_phi = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=hub["nodeNumber"], coordinate=2))

    r = T / (2.0 * math.pi)

    def theta(t):
        if t <= T:
            return w0 * (0.5 * t * t + r * r * (math.cos(t / r) - 1.0)) / T
        return w0 * (t - 0.5 * T)

    if a.uf == "symbolic":
        esym = exu.symbolic

        def offset(mbs, t, itemNumber, lOffset):
            return esym.IfThenElse(t <= T, w0 * (0.5 * t * t + r * r * (esym.cos(t / r) - 1.0)) / T, w0 * (t - 0.5 * T))
    else:
        def offset(mbs, t, itemNumber, lOffset):
            return theta(t)

    constraint = mbs.AddObject(CoordinateConstraint(markerNumbers=[mc_ground, mc_phi], offset=0.0,
                                                    offsetUserFunction=offset))
    if a.uf == "symbolic":
        from exudyn.utilities import CreateSymbolicUserFunction
        sym = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", constraint)
        mbs.SetObjectParameter(constraint, "offsetUserFunction", sym)
    tip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
                                   outputVariableType=exu.OutputVariableType.Position))

    s = exu.SimulationSettings()
    nsteps = int(round(a.t_end / a.step))
    s.timeIntegration.numberOfSteps = nsteps
    s.timeIntegration.endTime = a.t_end
    s.timeIntegration.verboseMode = a.verbose
    # Newton: modified (a Jacobian kept while it contracts) with a new Jacobian at every step, the
    # fastest of the three modes on 16 elements, h = 1e-3 s, omega0 = 15 (2.05 s against 2.84 s
    # full Newton and 6.1 s modified without the per-step update, Examples/ANCFrotatingCable2D.py's
    # choice; the same error 4.15e-5 m). The absolute residual tolerance 1e-6 (per coordinate):
    # at Exudyn's 1e-10 the first steps fail, the spin-up starting from rest (the relative
    # criterion cannot be met from a near-zero initial residual) and every step size is halved
    # down to 1e-7 s; 1e-6 does not limit the accuracy here (full Newton agrees to 2e-8 m).
    s.timeIntegration.newton.useModifiedNewton = a.newton != "full"
    s.timeIntegration.newton.modifiedNewtonJacUpdatePerStep = a.newton == "modified-jac"
    s.timeIntegration.newton.absoluteTolerance = a.abstol
    s.solutionSettings.writeSolutionToFile = False
    s.solutionSettings.sensorsWritePeriod = 0.01
    s.displayComputationTime = False
    s.displayStatistics = False
    s.linearSolverType = exu.LinearSolverType.EigenSparse if a.solver == "sparse" else exu.LinearSolverType.EXUdense

    c0 = time.process_time()
    mbs.Assemble()
    ok = mbs.SolveDynamic(s)
    cpu = time.process_time() - c0

    data = np.asarray(mbs.GetSensorStoredData(tip))  # t, x, y, z
    t = data[:, 0]
    th = np.array([theta(ti) for ti in t])
    c, sn = np.cos(th), np.sin(th)
    x, y = data[:, 1], data[:, 2]
    u = c * x + sn * y - L
    v = -sn * x + c * y
    with open(a.out, "w") as f:
        f.write("t,beam.tip_u,beam.tip_v\n")
        for row in zip(t, u, v):
            f.write("%.12g,%.12g,%.12g\n" % row)
    fast = int(hasattr(exu, "__useExudynFast") and bool(getattr(exu, "__useExudynFast")))
    print("cpu_s=%.4f steps=%d ok=%d fast=%d" % (cpu, nsteps, 1 if ok else 0, fast))
    return 0 if ok else 3


if __name__ == "__main__":
    sys.exit(main())

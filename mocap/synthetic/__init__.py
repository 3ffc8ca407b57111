"""Synthetic marker data: people × actions with ground-truth joint angles.

Each person has a *motion signature*: body size and proportions, cadence, a few
latent style factors that move the gait (stride, step width, toe-out, foot pitch at
landing and push-off, step clearance, knee flexion in stance, heel-rise timing) and
scale and offset the trunk, arm and head curves (interacting with the action: a
long-striding walker is not a long-striding stair climber in the same proportion), a
stance/swing timing shift and a left/right asymmetry.

The motion is built the way a body has to move, so that it is physically plausible:

1. **Feet.**  Each foot lands (heel first; toe first down stairs) at its place on the
   floor or on a stair tread, rolls flat, stays still while it carries the body, rolls
   over the toe and swings to the next place along quintic curves that match the
   rockers' position, velocity and acceleration and clear the floor (or the nosing).
2. **Centre of mass.**  It rides the centre of pressure, which rolls from heel to toe
   under each foot and passes from foot to foot in double support, like an inverted
   pendulum: the periodic solution of x'' = k(t)(x − p(t)) + L'(t)/h(t), where the last
   term is what the body's turning (the rate of its angular momentum about the centre of
   mass, from the posture) asks of the floor's force, so the floor can supply every
   acceleration and every moment.  Its height is what the supporting leg gives at
   its nominal knee flexion (walking, stairs: loading response, nearly straight in
   mid-stance), smoothed and kept within reach, or a spring-mass bounce with a
   ballistic flight phase (running).  The root follows from the centre of mass and the
   posture (segment masses, centres of mass and inertias of de Leva, as the check has them).
   Running, the trunk (with head and arms) turns against the legs about the lumbar joint
   so that the body's angular momentum stays constant in flight and changes in stance
   only as fast as the floor's force can turn it (:func:`~mocap.synthetic.balance._flight_turn`).
3. **Legs.**  Two-link inverse kinematics in 3-D gives hip flexion and abduction and
   the knee from the hip-to-ankle vector; the hip's axial rotation keeps the ankle's
   axial rotation at its template; the ankle takes the foot's orientation.  The heel
   rises during push-off as much as the knee's nominal flexion asks.

Stance feet are planted exactly (no skating, no penetration); the floor is flat for
walk and run, a staircase of ``STEP_RISE`` × ``STEP_GOING`` steps for ascend and descend
(two steps per cycle).  Measured with :func:`dynamics.humanoid.check.check_motion` (6 Hz
low-pass, the default people of seed 0, one cycle), walks need a residual force of
0.0–0.4 % body weight RMS, stairs 0.1–1.1 % (with 0.5 mm marker noise 1.0–2.3 % and
0.6–2.5 %), all plausible; runs 5.7–8.6 % (noisy 6.0–10.7 %) and a residual torque of
26–39 N·m (noisy 25–58; 59–89 before the trunk's turn), 3/6 plausible (noisy 4/6).  A
run's flight is ballistic and keeps its angular momentum on the check's own body model
(drift below 1 N·m·s per flight; the legs' swing alone changed it by 13–14); what the
check still reads is its 6 Hz low-pass spreading the 2.2-body-weight stances into the
flights (−10 to −17 % BW there) and its odd-reflection padding turning the falling
body's −g into +g at the ends of a one-cycle trial (residual force peak 29–37 %).

Forward kinematics puts three markers on each of the 15 segments of the
``synthetic15`` marker set (origin at the proximal joint centre, one marker
0.10 m anterior, one 0.10 m to the left), in a Z-up lab facing +X.

Modules, one job each: :mod:`~mocap.synthetic.people` (segments, markers, each person's
signature and body), :mod:`~mocap.synthetic.templates` (action curves, clinical angles),
:mod:`~mocap.synthetic.feet` (gaits and foot paths), :mod:`~mocap.synthetic.legs` (leg
inverse kinematics), :mod:`~mocap.synthetic.balance` (masses, centre of mass, root path),
:mod:`~mocap.synthetic.corpus` (trials and corpora). Forward kinematics is
:meth:`mocap.skeleton.Motion.forward_kinematics`.

Examples
--------
>>> from mocap.synthetic import synthesize_trial
>>> trial, truth = synthesize_trial(0, "walk")
>>> trial.points.shape[1], truth.rotations.shape[1]
(45, 15)
"""
from __future__ import annotations

from mocap.synthetic.balance import GRAVITY
from mocap.synthetic.corpus import generate_corpus, person_angles, synthesize_trial, truth_angles
from mocap.synthetic.feet import STEP_GOING
from mocap.synthetic.people import (ACTION_CYCLE_SECONDS, ACTIONS, MARKER_LABELS, MARKER_SPACING,
                                    PARENT_INDEX, PERSON_NAMES, SEGMENT_NAMES, SEGMENTS,
                                    STEP_RISE, GroundTruth, Person, cycle_seconds, lab_frames,
                                    make_people)

__all__ = ["ACTION_CYCLE_SECONDS", "ACTIONS", "GRAVITY", "MARKER_LABELS", "MARKER_SPACING",
           "PARENT_INDEX", "PERSON_NAMES", "SEGMENTS", "SEGMENT_NAMES", "STEP_GOING", "STEP_RISE",
           "GroundTruth", "Person", "cycle_seconds", "generate_corpus", "lab_frames",
           "make_people", "person_angles", "synthesize_trial", "truth_angles"]

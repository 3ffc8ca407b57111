"""dynamics: particle and mass-spring simulator, rigid bodies, Pinocchio humanoid.

The core simulator (lecture "Physical Simulations"):

- :mod:`dynamics.sim.particles`   ``Particles`` (position, velocity, mass, pinned, colour,
  temperature, age)
- :mod:`dynamics.sim.springs`     ``Springs`` (Voigt spring-dampers; numba force loop)
- :mod:`dynamics.sim.forces`      ``Gravity``, ``Drag``, ``Wind``, ``ForceCallback``
- :mod:`dynamics.sim.fluid`       ``FluidForce`` (pairwise attraction/repulsion, KD-tree)
- :mod:`dynamics.sim.collisions`  ``Plane``, ``Sphere``, ``Capsule``, ``Box`` colliders
- :mod:`dynamics.sim.builders`    ``rope``, ``cloth_grid``, ``lattice_block``, ``particle_block``
- :mod:`dynamics.sim.system`      ``System``: what the integrators step
- :mod:`dynamics.sim.integrators` explicit / symplectic Euler, RK4, implicit Euler; ``advance``
- :mod:`dynamics.sim.thermal`     heat diffusion, thermoelastic stiffness, melting
- :mod:`dynamics.sim.rigid`       rigid bodies (inertia tensors, Newton–Euler, quaternions)
- :mod:`dynamics.scenes.schema`   scene TOML (``docs/formats/scene-toml.md``): reading, type-checked tables, examples
- :mod:`dynamics.scenes.build`    scene document -> ``Scene`` (particle ``System``, rigid bodies)
- :mod:`dynamics.scenes.run`      ``run_scene`` -> ``SimulationResult`` -> ``.npz``
  (example scenes: ``data/scenes/*.toml``, the single copy)
- :mod:`dynamics.viz.render`      GIF / MP4 of a run

The Pinocchio humanoid (Pinocchio's model/data split: the model is built once, the
per-frame algorithms take it):

- :mod:`dynamics.humanoid.model`      ``Humanoid`` (Pinocchio model, inertias, contact points,
  its Data buffers), ``build_humanoid``
- :mod:`dynamics.humanoid.kinematics` q, v, a of a motion on the manifold (``motion_kinematics``,
  ``configurations``), quaternion helpers, ``centre_of_mass``
- :mod:`dynamics.humanoid.inverse`    ``rnea_batch``, ``contact_joint_torques``
- :mod:`dynamics.humanoid.contact`    friction-pyramid contact forces (``solve_contact_forces``,
  compiled NNLS), contact positions, ``estimate_floor``, ``foot_skate``
- :mod:`dynamics.humanoid.check`      the plausibility check (``check_motion``, ``CheckReport``,
  ``Thresholds``; ``docs/formats/check-json.md``)
- :mod:`dynamics.humanoid.tracking`   forward dynamics (ABA) of the humanoid tracking a motion
- :mod:`dynamics.humanoid.plant`      a root path from the feet of a joint-angle motion
- :mod:`dynamics.secondary`           cape and rope simulated on a moving body
- :mod:`dynamics.viz.animate`         stick-figure animations and the check plot (figures built
  without pyplot: no global matplotlib state)

A cape pinned to moving skeleton points, driven from outside every frame::

    from dynamics.sim.builders import cloth_grid
    from dynamics.sim.collisions import Capsule, Plane
    from dynamics.sim.forces import Drag, Gravity
    from dynamics.sim.system import System

    system = System()
    cape = cloth_grid(origin=shoulder_left, size=[0.45, 0.9], resolution=[12, 20],
                      mass=0.5, stiffness={"structural": 800, "shear": 100, "bend": 10},
                      damping={"structural": 0.05}, u_axis=shoulder_right - shoulder_left,
                      v_axis=[0, -1, 0], pin=["top"])
    index = system.add(cape)                       # global particle indices
    top = index[cape.named("top")]                 # the pinned row
    system.add_force(Gravity([0, -9.81, 0])); system.add_force(Drag(0.01))
    torso = Capsule(a=pelvis, b=neck, radius=0.15, margin=0.01); system.add_collider(torso)
    for frame in range(frames):
        system.drive_pinned(top, shoulder_points[frame + 1], dt)   # (12, 3) targets
        torso.move_to(pelvis_at[frame + 1], neck_at[frame + 1], dt=dt)
        system.step(dt, "implicit-euler")          # or "symplectic-euler" with small dt
        cape_positions[frame] = system.particles.position[index]

Importing this package is cheap: numba and scipy load with the submodules that need them.
"""

"""The FR3 cell as a MuJoCo model, built with :class:`mujoco.MjSpec`; nothing is downloaded.

Source of the arm: the FR3 MJCF and meshes shipped inside the ``franky-sim`` wheel (PyPI,
Apache-2.0; its ``assets/NOTICE`` says ``fr3.xml`` and the OBJ meshes come from Google
DeepMind's MuJoCo Menagerie, the STL collision meshes from Franka's ``franka_description``).
The kinematics and link inertias are Franka's published ones. Edits made here:

- the gripper fingers, their tendon, equality and actuator are removed: the task's held part is
  rigidly attached under the Franka Hand at ``mount_offset`` from the flange (part frame = TCP,
  its +z axis pointing back at the flange). The hand's collision mesh collides with the cell;
  the links' collision meshes are left out (the arm works above the fixture; without them the
  model compiles in a fraction of a second and the collision pass stays cheap), and so are the
  visual meshes unless ``FR3Params.visual`` asks for them (rendering);
- the position servos are replaced by torque motors: gain 1, no bias,
  ``ctrlrange = ±tau_max`` (87/87/87/87/12/12/12 N·m);
- joint ranges are the FR3 datasheet's; joint friction is Gaz et al.'s identification
  (RA-L 2019) with an optional static peak and Stribeck decay (:mod:`teachfit.robot.fr3.params`,
  off by default: the joints break away at ``F_s = r F_c`` and slide at
  ``F_c + (F_s - F_c) exp(-(dq/v_s)^2)``, ``F_c = phi1 / 2`` the Coulomb level of Gaz's
  sigmoid), no viscous ``damping``. MuJoCo
  ``frictionloss`` is set to the *static* level ``F_s``: MuJoCo solves it as a dry-friction
  constraint (static and sliding, implicit, stable at 1 ms), so the joint sticks until the
  load exceeds ``F_s``, and while it slides the constraint pushes back with ``F_s``. Each tick
  (between ``mj_step1`` and ``mj_step2``, :func:`teachfit.robot.fr3.kernel.stribeck`) a
  passive torque along the motion, ``(F_s - F_c) (1 - exp(-(dq/v_s)^2)) sign(dq)``, is added
  to ``qfrc_passive``: the sliding friction is then the Stribeck curve, ``F_c`` once the joint
  moves faster than a few ``v_s``. It is friction in the gears, on the motor side of the
  link-side torque sensors, so they read past it as past the constraint (``sensing``). Why
  not Gaz's sigmoid applied per tick: it is zero at zero speed, so applied as a torque it
  cannot hold anything still, whereas the real arm's gears do hold small loads; the sigmoid's
  smooth ramp (|dq| < ~0.2 rad/s) is below what the constraint resolves. Armature (reflected
  rotor inertia) keeps the Menagerie's values: Gaz et al. identify link-side parameters only;
- the arm's base stands at ``FR3Params.base_pos`` in the task's world frame, so the fixture
  stays where the task builds it; a wrist F/T site sits on the flange.

Contact model, and why it differs from the tasks' default. With the tasks' former contact
(``solimp`` impedance 0.95 from the first micrometre of penetration, ``solref`` time constant
2 ms = two steps) a part pressed with 6 N and slid at about 1 cm/s *hops*: it loses every
contact for a few ticks, lands, and is thrown up again with a restitution of about one, every
2 to 8 ms. The wrist signal is that train of impacts, white noise at 100 Hz (std 1.6 N on the
floating tool).
The energy comes from friction: at each landing the full-stiffness contact stops the sliding
contact points within one tick, and the friction impulse at the tip tips the part and throws it
up. It is not the mesh pieces (a primitive box sliding on a box hops too), nor the friction cone
(pyramidal or elliptic), ``impratio`` (0.03 to 100), ``noslip``, multi-point CCD, the solver
tolerance or the integrator (0.25 ms substeps hop too); without friction it does not happen.
What fixes it is a *progressive* contact, as real machined surfaces are (asperities first):
impedance rising from 0.05 at first touch to 0.99 over 0.5 mm, time constant 4 ms
(``FR3Params.contact_solimp`` / ``contact_solref``; the task's friction coefficient is kept).
The tasks now use a progressive contact too, with a stiffer 0.1 mm ramp from 0.1 (enough for
the floating tool); on the arm that one still loses contact now and then (lag-1 0.2-0.5), so
the arm keeps this softer one.
Landings are then absorbed over several ticks and the part stays on the surface; it sinks a few
tens of micrometres under the press, which the 0.2 mm clearance tolerates. The joints' dry
friction gets a 5 ms time constant (``joint_friction_solref``, MuJoCo's default is 20 ms): it
then sticks crisply instead of creeping and slipping in bursts, which shook the sliding part.

No stick-slip at the part/fixture contact: a MuJoCo contact has one friction coefficient per
direction (sliding, torsional, rolling), the same for sticking and for sliding, and its cone is
solved as a soft constraint without a velocity-dependent coefficient; a static coefficient above
the kinetic one would need a per-contact force applied from outside the solver each tick
(explicit, at the mesh pieces' many contact points), which is not done. Stick-slip on the arm
comes from its joints.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path

import mujoco
import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.robot.fr3.params import Q_MAX, Q_MIN, TAU_MAX, FR3Params
from teachfit.tasks.base import Task
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml

ARM_PREFIX = "fr3/"
JOINTS = tuple(f"{ARM_PREFIX}fr3_joint{i}" for i in range(1, 8))
HAND = f"{ARM_PREFIX}hand"
TCP_SITE = "tcp"
FLANGE_SITE = f"{ARM_PREFIX}flange"
FT_FORCE, FT_TORQUE = "ft_force", "ft_torque"
#: the link-side joint torque sensors: a torque sensor on a site at each joint's anchor
JOINT_TORQUE_SENSORS = tuple(f"{j}_tau" for j in JOINTS)
PART_PREFIX = "part/"
_PART_SRC = "held_part"
_FINGER_BODIES = ("left_finger", "right_finger")


@cache
def asset_dir() -> Path:
    """Folder of the FR3 model inside the installed ``franky-sim`` package (not imported)."""
    spec = importlib.util.find_spec("franky_sim")
    if spec is None or not spec.submodule_search_locations:
        raise TeachfitError("the FR3 model needs the 'franky-sim' package: pip install franky-sim")
    path = Path(next(iter(spec.submodule_search_locations))) / "assets"
    if not (path / "fr3.xml").is_file():
        raise TeachfitError(f"franky-sim ships no assets/fr3.xml under {path}")
    return path


def _cell_xml(task: Task, contact: ContactParams, timestep: float) -> str:
    """The task's cell (fixture, floor, lights) as MJCF, in the task's world frame."""
    scene = SceneXml(model=f"teachfit-fr3-{task.name}", timestep=timestep)
    world = scene.worldbody
    ET.SubElement(world, "light", pos="0.3 -0.3 1.2", dir="-0.3 0.3 -1", diffuse=".8 .8 .8")
    ET.SubElement(world, "light", pos="-0.6 0.4 1.4", dir="0.4 -0.3 -1", diffuse=".4 .4 .4")
    ET.SubElement(
        world,
        "geom",
        name="floor",
        type="plane",
        size="1 1 0.01",
        material="grid",
        contype="0",
        conaffinity="0",
    )
    task.scene.add_fixture(scene, contact)
    # the held part is built standing in the world, then moved onto the hand (its frame = TCP)
    part = ET.SubElement(world, "body", name=_PART_SRC)
    task.scene.add_held_part(part, scene, contact)
    return scene.to_string()


def _arm_spec(params: FR3Params) -> mujoco.MjSpec:
    """The FR3 arm with the edits listed in the module docstring (no actuators yet)."""
    root = asset_dir()
    arm = mujoco.MjSpec.from_file(str(root / "fr3.xml"))
    arm.meshdir = str(root / "meshes")
    for name in _FINGER_BODIES:
        arm.delete(arm.body(name))
    for item in [*arm.actuators, *arm.tendons, *arm.equalities, *arm.keys]:
        arm.delete(item)
    friction = params.static_friction()
    for i, name in enumerate(JOINTS):
        joint = arm.joint(name.removeprefix(ARM_PREFIX))
        joint.range = [Q_MIN[i], Q_MAX[i]]
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        joint.frictionloss = float(friction[i])
        joint.damping = np.zeros(3)
        joint.solref_friction = list(params.joint_friction_solref)
    hand = arm.body("hand")
    for geom in list(arm.geoms):
        visual = geom.contype == 0 and geom.conaffinity == 0
        if (visual and not params.visual) or (not visual and geom.parent.name != "hand"):
            arm.delete(geom)
    used = {g.meshname for g in arm.geoms}
    for mesh in list(arm.meshes):
        if mesh.name not in used:
            arm.delete(mesh)
    arm.compiler.degree = False
    hand.add_site(name=FLANGE_SITE.removeprefix(ARM_PREFIX), size=[0.004] * 3, rgba=[0, 0, 1, 1])
    return arm


#: the hand's lowest point stays this far (m) above the fixture when the part is inserted
HAND_CLEARANCE = 0.002
#: how deep (m) past the task's success depth the hand must be able to go
_EXTRA_DEPTH = 0.002


def fixture_top(task: Task) -> float:
    """Highest point (m, world z) of the task's colliding fixture geometry (planes excluded)."""
    model = mujoco.MjModel.from_xml_string(_cell_xml(task, ContactParams(), 0.001))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    part = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, _PART_SRC)
    top = float(task.surface_z)
    for g in range(model.ngeom):
        body = model.geom_bodyid[g]
        if model.body_rootid[body] == part or model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        if model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0:
            continue
        centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
        rz = data.geom_xmat[g].reshape(3, 3)[2]
        top = max(top, float(data.geom_xpos[g, 2] + rz @ centre + np.abs(rz) @ half))
    return top


def grasp_drop(task: Task) -> float:
    """How much lower (m) than flush under the hand the part is held: enough that the Franka
    Hand clears the fixture by :data:`HAND_CLEARANCE` with the part ``_EXTRA_DEPTH`` past its
    success depth (0 for every built-in task but ``socket3d``, whose recess wall stands 22 mm
    above its floor and would stop the hand 0.4 mm short of success: the part is then held
    lower in the fingers, as a person would grasp it)."""
    hand_z = (
        float(task.hole2world.pos[2])
        - float(task.success_depth)
        - _EXTRA_DEPTH
        + float(task.scene.held_part_length)
    )
    return max(0.0, fixture_top(task) + HAND_CLEARANCE - hand_z)


def build_fr3_spec(task: Task, params: FR3Params | None = None) -> mujoco.MjSpec:
    """The whole cell: the task's fixture, the FR3 on its base, the held part on the hand,
    torque motors, the wrist F/T sensors and the joint torque sensors."""
    params = params or FR3Params()
    contact = dataclasses.replace(
        task.scene.contact or ContactParams(),
        solref=params.contact_solref,
        solimp=params.contact_solimp,
    )
    spec = mujoco.MjSpec.from_string(_cell_xml(task, contact, params.timestep))
    base = spec.worldbody.add_frame(pos=list(params.base_pos))
    base.attach_body(_arm_spec(params).body("base"), ARM_PREFIX, "")
    # part frame = TCP, +z back towards the flange: rotated by pi about the hand's x axis
    mount = spec.body(HAND).add_frame(
        pos=[0.0, 0.0, params.mount_offset + task.scene.held_part_length + grasp_drop(task)],
        quat=[0.0, 1.0, 0.0, 0.0],
    )
    spec.copy_during_attach = True
    part = mount.attach_body(spec.body(_PART_SRC), PART_PREFIX, "")
    spec.delete(spec.body(_PART_SRC))
    part.add_site(name=TCP_SITE, size=[0.002] * 3, rgba=[0, 1, 0, 1])
    for i, name in enumerate(JOINTS):
        spec.add_actuator(
            name=f"{name}_motor",
            target=name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gaintype=mujoco.mjtGain.mjGAIN_FIXED,
            gainprm=[1.0] + [0.0] * 9,
            biastype=mujoco.mjtBias.mjBIAS_NONE,
            ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            ctrlrange=[-TAU_MAX[i], TAU_MAX[i]],
        )
    spec.add_sensor(
        name=FT_FORCE,
        type=mujoco.mjtSensor.mjSENS_FORCE,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        objname=FLANGE_SITE,
    )
    spec.add_sensor(
        name=FT_TORQUE,
        type=mujoco.mjtSensor.mjSENS_TORQUE,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        objname=FLANGE_SITE,
    )
    for name, sensor in zip(JOINTS, JOINT_TORQUE_SENSORS, strict=True):
        # MuJoCo's torque between the link and its parent, on the joint axis, is what a
        # link-side joint torque sensor reads: motor torque past gear friction and rotor inertia
        joint = spec.joint(name)
        joint.parent.add_site(name=sensor, pos=list(joint.pos), size=[0.001] * 3, group=5)
        spec.add_sensor(
            name=sensor,
            type=mujoco.mjtSensor.mjSENS_TORQUE,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=sensor,
        )
    return spec


def build_fr3_model(task: Task, params: FR3Params | None = None) -> mujoco.MjModel:
    """Compiled :func:`build_fr3_spec`."""
    return build_fr3_spec(task, params).compile()

"""Contact views: what every interaction sees of a system (DESIGN "What every system offers").

A system's ``contact_view()`` returns one of three views, built once at construction and
reading the system's live state. Contacts, attachments, stand-in fields, aerodynamics and the
ground read only these, never a type check or a private attribute, so a new kind of system
plugs into every interaction by offering a view:

* ``PointsView``: point masses (cloth, nets, ropes, cords): positions, velocities, inverse
  masses, the triangles or segments joining them, and forces on points with optional Jacobian
  blocks for implicit integrators; optionally a sub-cycling hook (``subcycle``) through which
  a stiff interaction is evaluated inside the system's own substeps.
* ``BodiesView``: rigid parts (a ball: one part; a figure: its segments): per part a
  body-frame mesh and an analytic primitive, its pose, the velocity and free acceleration of
  its centre of mass, its mass and inverse inertia, and wrenches applied at world points.
* ``ShapeView``: an immovable analytic shape answering signed distances (a plane, box,
  capsule, sphere or mesh collider); infinitely heavy.

Lengths in m, velocities m/s, forces N, masses kg; rotations are (3,3) matrices taking a
part's frame to the world.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
import numpy as np



class _View:
    """What every view shares: the system it shows, its name and its time (s)."""

    def __init__(self, system):
        self.system = system

    @property
    def name(self) -> str:
        return self.system.name

    @property
    def time(self) -> float:
        return self.system.time


class PointsView(_View):
    """Point masses. Live arrays: ``x``, ``v`` (n,3); ``inverse_mass`` (n,) 1/kg (0 for fixed
    points); ``masses`` (n,). Topology: ``triangles`` (m,3) or None, ``segments`` (s,2) (the
    springs: what cords collide as). ``thickness`` (m): the elements' skin (a cord's radius).
    ``points``: the kernels' springs.Points bundle of the same arrays.
    ``jacobians``: whether ``apply`` uses Jacobian blocks (an implicit integrator)."""

    kind = "points"

    def __init__(self, system, points, triangles=None, segments=None, thickness=0.0,
                 jacobians=False):
        super().__init__(system)
        self.points = points
        self.x, self.v, self.masses = points.x, points.v, points.m
        self.triangles = triangles
        self.segments = segments
        self.thickness = float(thickness)
        self.jacobians = bool(jacobians)

    @property
    def inverse_mass(self) -> np.ndarray:
        """(n,) 1/kg, 0 for fixed points."""
        return np.where(self.points.fixed, 0.0, 1.0 / self.points.m)

    @property
    def movable(self) -> bool:
        from .base import Role
        return self.system.role is Role.DYNAMIC

    def accelerations(self) -> np.ndarray:
        """(n,3) accelerations (m/s^2) from every force now acting (internal and held)."""
        return self.system.accelerations()

    def apply(self, idx, forces, dfdx=None, dfdv=None, vref=None) -> None:
        """Add forces (N) on points idx; dfdx, dfdv (k,3,3) their Jacobians (N/m, N s/m) and
        vref (k,3) the velocity (m/s) of whatever the force is relative to (a contact's other
        body). Jacobians are dropped when the integrator does not use them."""
        if self.jacobians and dfdx is not None:
            self.system.add_point_forces(idx, forces, dfdx, dfdv, vref)
        else:
            self.system.add_point_forces(idx, forces)

    def substeps(self, h: float) -> int:
        """How many substeps the system takes in a coupling step of h (s)."""
        return self.system.substeps(h)

    def subcycle(self, colliders, elements) -> bool:
        """The sub-cycling hook: ask the system to evaluate the kernels.contact.Colliders
        against ``elements`` ((s,2) point pairs: segments, or (p, p) for points) at every
        substep of its next advance, filling ``colliders.impulses``. False when it cannot
        (the interaction then exchanges forces once per coupling step)."""
        return self.system.subcycle(colliders, elements)


class RigidParts(ABC):
    """What a system implements to be seen as rigid parts (``BodiesView``): a rigid body (one
    part), a figure (its segments), a keyframed or motion-captured body."""

    @abstractmethod
    def part_poses(self):
        """(origins (k,3) m, rotations (k,3,3)) of the parts' frames."""

    @abstractmethod
    def part_centres(self) -> np.ndarray:
        """(k,3) centres of mass (m)."""

    @abstractmethod
    def part_velocities(self, parts=None):
        """(linear (k,3) m/s at the centres of mass, angular (k,3) rad/s) of every part, or of
        the parts listed (indices, in that order)."""

    def part_accelerations(self) -> np.ndarray:
        """(k,3) free accelerations of the centres of mass (m/s^2): with no interaction acting,
        e.g. gravity; zero when unknown."""
        return np.zeros((len(self.contact_view().names), 3))

    def part_inverse_inertias(self) -> np.ndarray:
        """(k,3,3) world inverse inertias (1/(kg m^2)) a contact may use; zero by default."""
        return np.zeros((len(self.contact_view().names), 3, 3))

    @abstractmethod
    def centre_of_mass(self) -> np.ndarray:
        """(3,) the system's centre of mass (m)."""

    def add_part_wrench(self, part, force, torque=None, point=None, dfdx=None, dfdv=None):
        """Add a force (N) at a world point to a part (see BodiesView.apply); systems that
        cannot be pushed ignore it. A system that can carry points tied to it (a free rigid
        body) also takes ``carried`` (see BodiesView.apply)."""

    def mark_touching(self, parts):
        """Parts (indices) a contact touched this step, for the system's own sensors (a
        figure's foot-contact events); ignored by systems without sensors."""


class BodiesView(_View):
    """Rigid parts. ``names`` (k,); ``meshes`` [(vertices (v,3), triangles (t,3))] in each
    part's frame; ``primitives`` [Primitive or None]; ``masses`` (k,) kg (inf when the system
    cannot be pushed); ``movable``: whether forces move it (a dynamic system). The system
    supplies the live pose and motion through the methods below."""

    kind = "bodies"

    def __init__(self, system, names, meshes, primitives, masses, movable):
        super().__init__(system)
        self.names = list(names)
        self.meshes = meshes
        self.primitives = primitives
        self.masses = np.asarray(masses, dtype=float)
        self.movable = bool(movable)
        self.count = len(self.names)
        # m, from each part's frame origin: bounds every vertex of its mesh
        self.reach = np.array([float(np.linalg.norm(v, axis=1).max()) if len(v) else 0.0
                               for v, _ in meshes])

    def part(self, name: str) -> int:
        """Index of the part called ``name``."""
        return self.names.index(name)

    def poses(self):
        """(origins (k,3) m, rotations (k,3,3)) of the parts' frames."""
        return self.system.part_poses()

    def centres(self) -> np.ndarray:
        """(k,3) the parts' centres of mass (m)."""
        return self.system.part_centres()

    def velocities(self, parts=None):
        """(linear (k,3) m/s of each centre of mass, angular (k,3) rad/s), of every part or of
        the parts listed."""
        return self.system.part_velocities(parts)

    def free_accelerations(self) -> np.ndarray:
        """(k,3) m/s^2: each centre of mass's acceleration with no interaction acting (free
        fall; zero where it is not known, e.g. a figure's servos), the same whatever order the
        interactions run in."""
        return self.system.part_accelerations()

    def inverse_inertias(self) -> np.ndarray:
        """(k,3,3) 1/(kg m^2): each part's world inverse inertia as a contact may use it (zero
        for parts that cannot be pushed, or whose rotation joints stiffen)."""
        return self.system.part_inverse_inertias()

    def centre_of_mass(self) -> np.ndarray:
        """(3,) m: the whole system's centre of mass (torques in force logs are about it)."""
        return self.system.centre_of_mass()

    def apply(self, part: int, force, torque=None, point=None, dfdx=None, dfdv=None,
              carried=None) -> None:
        """Add a force (N) at a world point (m; default the part's centre of mass) and an extra
        torque (N m) to a part; dfdx, dfdv (3,3) the force's Jacobians with respect to the
        part's position and velocity (a free rigid body integrates a stiff force with them);
        carried: (mass kg, inertia (3,3) kg m^2 about the part's centre of mass, world axes)
        of points tied to the part that it carries over the step (their other forces being
        in force and torque; only systems that take it: a free rigid body). Ignored when the
        system cannot be pushed."""
        if not self.movable:
            return
        if carried is None:
            self.system.add_part_wrench(part, force, torque, point, dfdx, dfdv)
        else:
            self.system.add_part_wrench(part, force, torque, point, dfdx, dfdv, carried=carried)

    def touched(self, parts) -> None:
        """Tell the system that a contact touches these parts (indices) this step: sensing,
        not force (a figure's state machine reads foot contact from it)."""
        if self.movable:
            self.system.mark_touching(parts)


class ShapeView(_View):
    """An immovable analytic shape: ``distance(points) -> (s (n,), normals (n,3))``, the signed
    distance (m, negative inside) and the outward normal; ``depth`` (m or None): how far behind
    its surface a point still counts as inside (a one-sided mesh); ``height`` for a plane z =
    height (m), else None."""

    kind = "shape"
    movable = False

    def __init__(self, system, distance, height=None):
        super().__init__(system)
        self.distance = distance
        self.height = height

"""Preview cameras: parse ``--camera`` specs, frame a run by default, build GL matrices."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError

UP = np.array([0.0, 0.0, 1.0])  # +z up


@dataclass(frozen=True)
class Camera:
    """A pinhole camera: eye and target in m (world, +z up), vertical field of view in deg."""
    eye: tuple
    target: tuple
    fov_deg: float = 35.0

    def spec(self) -> str:
        """The ``--camera`` text that reproduces this camera."""
        f = lambda v: ",".join(f"{x:.3f}" for x in v)  # noqa: E731
        return f"{f(self.eye)}:{f(self.target)}:{self.fov_deg:g}"

    def basis(self):
        """(right, up, forward) unit vectors of the view."""
        eye, target = np.asarray(self.eye, float), np.asarray(self.target, float)
        fwd = target - eye
        fwd /= np.linalg.norm(fwd)
        up_hint = UP if abs(fwd @ UP) < 0.999 else np.array([0.0, 1.0, 0.0])
        right = np.cross(fwd, up_hint)
        right /= np.linalg.norm(right)
        return right, np.cross(right, fwd), fwd

    def view(self) -> np.ndarray:
        """World-to-camera matrix (4,4), OpenGL convention (camera looks down -z)."""
        r, u, f = self.basis()
        eye = np.asarray(self.eye, float)
        m = np.eye(4)
        m[0, :3], m[1, :3], m[2, :3] = r, u, -f
        m[:3, 3] = -m[:3, :3] @ eye
        return m

    def projection(self, aspect: float, near: float, far: float) -> np.ndarray:
        """Perspective matrix (4,4) for width/height ``aspect``; near and far in m."""
        t = 1.0 / math.tan(math.radians(self.fov_deg) / 2)
        m = np.zeros((4, 4))
        m[0, 0], m[1, 1] = t / aspect, t
        m[2, 2] = (far + near) / (near - far)
        m[2, 3] = 2 * far * near / (near - far)
        m[3, 2] = -1.0
        return m


def parse_camera(spec: str) -> Camera:
    """``"eye_x,eye_y,eye_z:target_x,target_y,target_z[:fov_deg]"`` (m, m, degrees)."""
    fix = ('expected "eye_x,eye_y,eye_z:target_x,target_y,target_z[:fov_deg]", '
           'e.g. "2,-6,2:0,0,1.5:35"')
    parts = str(spec).split(":")
    if len(parts) not in (2, 3):
        raise ParameterError(f"--camera {spec!r}: {fix}")
    try:
        eye = tuple(float(x) for x in parts[0].split(","))
        target = tuple(float(x) for x in parts[1].split(","))
        fov = float(parts[2]) if len(parts) == 3 else 35.0
    except ValueError:
        raise ParameterError(f"--camera {spec!r}: not numbers; {fix}") from None
    if len(eye) != 3 or len(target) != 3:
        raise ParameterError(f"--camera {spec!r}: eye and target need 3 coordinates each; {fix}")
    if not all(math.isfinite(x) for x in eye + target + (fov,)):
        raise ParameterError(f"--camera {spec!r}: coordinates must be finite; {fix}")
    if not 1.0 <= fov <= 150.0:
        raise ParameterError(f"--camera {spec!r}: field of view {fov:g} deg is out of range; "
                             "use 1 to 150 degrees")
    if np.linalg.norm(np.subtract(eye, target)) < 1e-6:
        raise ParameterError(f"--camera {spec!r}: eye and target are the same point; move the "
                             "eye away from the target")
    return Camera(eye, target, fov)


def default_camera(lo, hi, aspect: float, fov_deg: float = 35.0, azimuth_deg: float = -65.0,
                   elevation_deg: float = 12.0, margin: float = 0.08) -> Camera:
    """A camera that sees the whole box [lo, hi] (m) from a three-quarter view slightly above.

    azimuth is measured from +x about +z (-90 looks along +y); the distance is the smallest
    that keeps every corner of the box inside the frame with ``margin`` (fraction) to spare.
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    # a flat or point-like box (a single resting body) still gets a sensible view
    size = np.maximum(hi - lo, 0.2)
    centre = (lo + hi) / 2
    lo, hi = centre - size / 2, centre + size / 2
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    back = np.array([math.cos(az) * math.cos(el), math.sin(az) * math.cos(el), math.sin(el)])
    probe = Camera(tuple(centre + back), tuple(centre), fov_deg)
    right, up, fwd = probe.basis()
    tan_v = math.tan(math.radians(fov_deg) / 2) * (1 - margin)
    tan_h = tan_v * aspect
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])]) - centre
    # corner c is inside when |c.right| <= (d + c.fwd) tan_h (same for up): solve for d
    depth = corners @ fwd
    need = np.maximum(np.abs(corners @ right) / tan_h, np.abs(corners @ up) / tan_v) - depth
    dist = max(float(need.max()), 0.5)
    return Camera(tuple(centre + back * dist), tuple(centre), fov_deg)


@dataclass(frozen=True)
class TrackingCamera:
    """A camera that travels with a system (the jumper, the rider, the runner): it looks at
    the system's position plus ``target_offset`` from there plus ``offset`` (m, world axes),
    with vertical field of view fov_deg. ``axes`` (1 or 0 per world axis) says which
    coordinates it follows; on the others it holds ``hold`` (m). The followed path is low-pass
    filtered forward and backward in time with time constant smooth_s (s), so the camera
    eases along without lag or jitter. A system's position: a body's, a figure's root segment
    (its first part), or the mean of its points."""
    follow: str
    offset: tuple
    target_offset: tuple = (0.0, 0.0, 0.0)
    fov_deg: float = 35.0
    axes: tuple = (1, 1, 1)
    hold: tuple = (0.0, 0.0, 0.0)
    smooth_s: float = 0.4

    def spec(self) -> str:
        return f"tracking {self.follow}, offset {tuple(round(v, 3) for v in self.offset)} m"

    def path(self, run, times) -> list:
        """The Camera at each of ``times`` (s)."""
        times = np.asarray(times, dtype=float)
        p = np.array([_position(run, self.follow, t) for t in times])
        if len(times) > 1 and self.smooth_s > 0:
            p = _smooth(p, float(np.median(np.diff(times))) / self.smooth_s)
        axes, hold = np.asarray(self.axes, float), np.asarray(self.hold, float)
        target = axes * p + (1 - axes) * hold + np.asarray(self.target_offset, float)
        eye = target + np.asarray(self.offset, float)
        return [Camera(tuple(e), tuple(c), self.fov_deg) for e, c in zip(eye, target)]


def _position(run, name: str, t: float) -> np.ndarray:
    st = run.sample(name, t)
    if "position" in st:
        return np.asarray(st["position"], float)
    if "segment_positions" in st:
        return np.asarray(st["segment_positions"][0], float)
    return np.nanmean(np.asarray(st["points"], float), axis=0)


def _smooth(p: np.ndarray, a: float) -> np.ndarray:
    """Forward then backward first-order low-pass (zero phase); a = step / time constant."""
    k = 1.0 - math.exp(-a)
    out = p.copy()
    for direction in (range(1, len(p)), range(len(p) - 2, -1, -1)):
        for i in direction:
            j = i - 1 if direction.step == 1 else i + 1
            out[i] = out[j] + k * (out[i] - out[j])
    return out


def cameras(camera, run, times, aspect: float) -> list:
    """One Camera per time (s): a fixed Camera, a TrackingCamera's path, or (None) the
    default framing of every animated system over the whole run."""
    if camera is None:
        lo, hi = run.bounds()
        camera = default_camera(lo, hi, aspect)
    if isinstance(camera, TrackingCamera):
        return camera.path(run, times)
    return [camera] * len(times)

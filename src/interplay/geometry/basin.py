"""Basins for the water: a grid of columns, a fluid mask (walls where it is False), a bed with
a sloping shore, and the still-water depth of every column."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..params import param

SHAPES = ("ellipse", "rectangle")


@dataclass(frozen=True)
class BasinParams:
    """A basin centred on the origin. size_x, size_y: extent of the grid (m); cells: columns
    along x (the spacing is size_x / cells); depth: still water over the flat bed at z = 0 (m);
    shore: width (m) of the bed's slope up to the rim; rim: height of the bed at the rim as a
    multiple of depth (> 1 leaves a dry beach); shape: ellipse or rectangle."""
    size_x: float = param(2.0, "m", ge=0.01, le=1000.0, doc="grid extent along x")
    size_y: float = param(2.0, "m", ge=0.01, le=1000.0, doc="grid extent along y")
    # columns along x; along y in proportion: cells^2 size_y / size_x columns in all
    cells: int = param(128, "columns", ge=4, le=4096, cost=("columns", 2))
    depth: float = param(0.3, "m", ge=1e-3, le=100.0, doc="still water over the flat bed")
    shore: float = param(0.3, "m", ge=0.0, le=1000.0, doc="width of the sloping shore")
    rim: float = param(1.3, "x depth", ge=1.0, le=100.0, doc="bed height at the rim")
    shape: str = param("ellipse", choices=SHAPES)

    def __post_init__(self):
        # the column count is cells^2 size_y / size_x: bound the aspect so cells bounds it
        if not 0.01 <= self.size_y / self.size_x <= 100.0:
            raise ParameterError(f"size_y / size_x = {self.size_y / self.size_x:.3g} must be "
                                 "within 0.01 to 100 (a basin, not a channel)")


@dataclass(frozen=True)
class Basin:
    """Column grid: bed heights (m), fluid mask, depths (m), spacing l (m), origin: the centre
    (m) of column (0, 0)."""
    bed: np.ndarray
    fluid: np.ndarray
    depth: np.ndarray
    spacing: float
    origin: tuple


def basin(p: BasinParams) -> Basin:
    """Build the basin; ParameterError for sizes, depths or shapes out of range."""
    sx = require_positive("basin", "size_x", p.size_x, "m")
    sy = require_positive("basin", "size_y", p.size_y, "m")
    depth = require_nonnegative("basin", "depth", p.depth, "m")
    shore = require_nonnegative("basin", "shore", p.shore, "m")
    if int(p.cells) < 4:
        raise ParameterError(f"basin: cells must be at least 4, got {p.cells}")
    if p.shape not in SHAPES:
        raise ParameterError(f"basin: unknown shape {p.shape!r}; choose {' or '.join(SHAPES)}")
    if not p.rim >= 1.0:
        raise ParameterError(f"basin: rim must be >= 1 (x depth), got {p.rim}; below 1 the "
                             "water would stand above the shore")
    nx = int(p.cells)
    l = sx / nx
    ny = max(4, int(round(sy / l)))
    x = (np.arange(nx) - 0.5 * (nx - 1)) * l
    y = (np.arange(ny) - 0.5 * (ny - 1)) * l
    X, Y = np.meshgrid(x, y, indexing="ij")
    # walls: one ring of columns at least, so the outer pipes are closed
    ax, ay = 0.5 * sx - l, 0.5 * ny * l - l
    if p.shape == "ellipse":
        rho = np.sqrt((X / ax) ** 2 + (Y / ay) ** 2)
        fluid = rho <= 1.0
        inset = (1.0 - rho) * min(ax, ay)  # distance to the rim, approximately (m)
    else:
        fluid = (np.abs(X) <= ax) & (np.abs(Y) <= ay)
        inset = np.minimum(ax - np.abs(X), ay - np.abs(Y))
    rim = p.rim * depth
    if shore > 0.0:
        bed = rim * np.clip(1.0 - inset / shore, 0.0, 1.0)
    else:
        bed = np.zeros_like(X)
    bed = np.where(fluid, bed, rim)
    d = np.where(fluid, np.maximum(depth - bed, 0.0), 0.0)
    return Basin(bed=bed, fluid=fluid, depth=d, spacing=l, origin=(float(x[0]), float(y[0])))


def banks(b: Basin, name: str, size: float, color=(0.30, 0.42, 0.20)):
    """The ground around a basin (a setpieces.Piece): flat at the height of its rim, out to
    size (m) from the centre, with a hole where the basin's own bed (over its column centres)
    is drawn."""
    from .setpieces import ground_around
    nx, ny = b.bed.shape
    lo = np.asarray(b.origin, float)
    hi = lo + b.spacing * np.array([nx - 1, ny - 1])
    return ground_around(lo, hi, float(b.bed.max()), size, name, color)


def terrain(b: Basin):
    """height(x, y) -> z (m): the basin's bed (bilinear between column centres) inside its
    grid, the rim's height (the ground around it) outside."""
    from scipy.interpolate import RegularGridInterpolator
    nx, ny = b.bed.shape
    x = b.origin[0] + b.spacing * np.arange(nx)
    y = b.origin[1] + b.spacing * np.arange(ny)
    f = RegularGridInterpolator((x, y), b.bed, bounds_error=False, fill_value=float(b.bed.max()))
    return lambda px, py: float(f([[px, py]])[0])

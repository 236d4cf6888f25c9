"""Water kernels (O'Brien & Hodgins 1995): virtual-pipe columns, spray particles, bodies.

Bodies are solids (kernels/lids.py: ellipsoids, capsules, boxes) registered as lids over the
columns they shadow (lids.py ``add_solids``, ``group_lids``); ``heads`` turns the lids into external
pressure and ``solid_loads`` gives each solid the water's push back.

Grid: column (i, j) has its centre at (x0 + i l, y0 + j l); arrays are (nx, ny). Each pipe is
stored once, from a column to its neighbour in direction k: +x, +y, +x+y, +x-y, so
``Q[k, i, j]`` (m^3/s) is the flow from (i, j) to (i + DI[k], j + DJ[k]).

Heads (m): the water surface eta = bed + V / l^2 and the pressure head H = eta + ext, where
ext = p_ext / (rho g) is the external pressure bodies exert (see ``heads``: their lids). The
atmospheric pressure p0 is the same in every column and cancels.

Flow: Qdot = c (p_a - p_b) / (rho L) = c g (H_a - H_b) / L with L the pipe length (l or
l sqrt 2) and c = w d the pipe cross-section: w = l / (1 + sqrt 2) (our choice: with 8 pipes
this makes the linear wave speed exactly sqrt(g d)) and d the water depth above the pipe's sill
(the higher of the two beds), so dry pipes carry nothing. The volume moves by dt times the
*new* flow, i.e. the flow is staggered half a step (leapfrog): the flow over the step is its
midpoint value. The trapezoid average of old and new flow has |amplification|^2 =
1 + (omega dt)^2 / 2 > 1 for every wave and grows without bound; the staggered form conserves
wave energy and is stable for omega dt < 2, i.e. dt < l / sqrt(g d) (we keep 0.7 of it).
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .lids import content, lid_sample, merged, run_end, column_level

SQRT2 = math.sqrt(2.0)
#: floor on the depth (m) used to turn a column's flows into a velocity (no 0/0 when dry)
VELOCITY_DEPTH_FLOOR = 1e-3
#: outflow limit as a fraction of the column's volume: rounding can never make it negative
_KEEP = 1.0 - 1e-12
#: State.track: peak airborne particles, shallowest fluid column (m), highest particle (m),
#: particles emitted in all
PEAK, MIN_DEPTH, HIGHEST, EMITTED = 0, 1, 2, 3
TRACKED = 4


class Grid(NamedTuple):
    """The basin: bed (nx, ny) heights (m), fluid (nx, ny) mask, pipe (4, nx, ny) which pipes
    join two fluid columns, nearest (nx, ny) the flat index of the nearest fluid column (where
    spray landing on a wall goes), area l^2 (m^2), x0, y0 the centre of column (0, 0) (m),
    l the column width (m), w the pipe width (m)."""
    bed: np.ndarray
    fluid: np.ndarray
    pipe: np.ndarray
    nearest: np.ndarray
    area: float
    x0: float
    y0: float
    l: float
    w: float


class State(NamedTuple):
    """The water's state: V (nx, ny) column volumes (m^3), Q (4, nx, ny) pipe flows (m^3/s),
    ext (nx, ny) the external pressure head (m), rate (nx, ny) the surface's vertical speed
    (m/s), px, pv (cap, 3) spray positions (m) and velocities (m/s), track (TRACKED,): what
    the run has seen (the indices below)."""
    V: np.ndarray
    Q: np.ndarray
    ext: np.ndarray
    rate: np.ndarray
    px: np.ndarray
    pv: np.ndarray
    track: np.ndarray


class Settings(NamedTuple):
    """g (m/s^2); kappa (-) the bodies' penalty head per metre; damping and body_damping (1/s)
    pipe friction; cfl the substep as a fraction of the wave-speed limit; spray: on, threshold
    (m/s), fraction (-), vp the particle volume (m^3), radius (m), drag (1/m)."""
    g: float
    kappa: float
    damping: float
    body_damping: float
    cfl: float
    spray: bool
    threshold: float
    fraction: float
    vp: float
    radius: float
    drag: float


class Scratch(NamedTuple):
    """Per-step work arrays (nx, ny): the surface eta, the pressure head H, and out."""
    eta: np.ndarray
    H: np.ndarray
    out: np.ndarray


@njit(cache=True, inline="always")
def _dir(k):
    if k == 0:
        return 1, 0
    if k == 1:
        return 0, 1
    if k == 2:
        return 1, 1
    return 1, -1


@njit(cache=True)
def heads(grid, V, lids, n_lid, kappa, ext, eta, H):
    """Fill the surface eta, the external pressure head ext and the pressure head H (m).

    Bodies are given as *lids*: a column (flat index) with, at each of its sample points, the
    bottom and top (m) of a body's vertical chord, and a volume scale. Within a column the
    water is hydrostatic: the free part stands at H, the part under the bodies is held down
    by the pressure they exert (``content``; several bodies over one column are packed,
    ``merged``). ext = H - eta is the bodies' pressure head; it is a function of the water's
    own state, so the coupling stores and returns energy like a spring instead of pumping
    it."""
    bed, area = grid.bed, grid.area
    cell = lids.cell
    nx, ny = V.shape
    inv = 1.0 / area
    for i in range(nx):
        for j in range(ny):
            eta[i, j] = bed[i, j] + V[i, j] * inv
    k = 0
    while k < n_lid:
        k1 = run_end(cell, k, n_lid)
        i, j = cell[k] // ny, cell[k] % ny
        ext[i, j] = column_level(eta[i, j], bed[i, j], lids, k, k1, kappa) - eta[i, j]
        k = k1
    for i in range(nx):
        for j in range(ny):
            H[i, j] = eta[i, j] + ext[i, j]


@njit(cache=True)
def max_depth(V, fluid, area):
    """Largest water depth (m) over the fluid columns."""
    nx, ny = V.shape
    m = 0.0
    for i in range(nx):
        for j in range(ny):
            if fluid[i, j] and V[i, j] > m:
                m = V[i, j]
    return m / area


@njit(cache=True, inline="always")
def column_velocity(Q, V, pipe, i, j, area, w):
    """Horizontal water velocity (m/s) of column (i, j): the mean of the pipe velocities on
    both sides of it, sum_k (Q_out + Q_in) e_k / (4 w d) (exact for a uniform flow)."""
    nx, ny = V.shape
    sx = 0.0
    sy = 0.0
    for k in range(4):
        di, dj = _dir(k)
        q = Q[k, i, j]
        a, b = i - di, j - dj
        if a >= 0 and b >= 0 and b < ny and pipe[k, a, b]:
            q += Q[k, a, b]
        if k < 2:
            sx += q * di
            sy += q * dj
        else:
            sx += q * di / SQRT2
            sy += q * dj / SQRT2
    d = max(V[i, j] / area, VELOCITY_DEPTH_FLOOR)
    return sx / (4.0 * w * d), sy / (4.0 * w * d)


@njit(cache=True)
def flow_step(grid, state, lids, n_lid, settings, scratch, dt):
    """One step of the volume model: flows, outflow limiting, volumes. ``rate`` receives the
    surface's vertical speed dV/dt / l^2 (m/s). Every pipe moves the same volume out of one
    column and into the other, so the total is conserved to round-off."""
    bed, pipe, area, l, w = grid.bed, grid.pipe, grid.area, grid.l, grid.w
    V, Q, ext, rate = state.V, state.Q, state.ext, state.rate
    g, damping, body_damping = settings.g, settings.damping, settings.body_damping
    eta, H, out = scratch
    nx, ny = V.shape
    heads(grid, V, lids, n_lid, settings.kappa, ext, eta, H)
    keep = 1.0 / (1.0 + damping * dt)  # implicit linear pipe friction (1/s)
    # under a body the penalty makes a stiff, light cavity whose trapped waves nothing would
    # damp; the body's wetted surface does (a viscous boundary layer): body_damping (1/s)
    keep_body = 1.0 / (1.0 + (damping + body_damping) * dt)
    for k in range(4):
        di, dj = _dir(k)
        coef = dt * w * g / (l * (SQRT2 if k >= 2 else 1.0))
        for i in range(nx):
            for j in range(ny):
                if not pipe[k, i, j]:
                    continue
                a, b = i + di, j + dj
                sill = max(eta[i, j], eta[a, b]) - max(bed[i, j], bed[a, b])
                if sill > 0.0:
                    kk = keep_body if ext[i, j] > 0.0 or ext[a, b] > 0.0 else keep
                    Q[k, i, j] = (Q[k, i, j] + coef * sill * (H[i, j] - H[a, b])) * kk
                else:
                    Q[k, i, j] = 0.0
    # outflow limiting: a column never gives more than it holds
    out[:] = 0.0
    for k in range(4):
        di, dj = _dir(k)
        for i in range(nx):
            for j in range(ny):
                q = Q[k, i, j]
                if q > 0.0:
                    out[i, j] += q
                elif q < 0.0:
                    out[i + di, j + dj] -= q
    for i in range(nx):
        for j in range(ny):
            o = out[i, j] * dt
            if o > V[i, j] * _KEEP:
                out[i, j] = V[i, j] * _KEEP / o
            else:
                out[i, j] = 1.0
    for k in range(4):
        di, dj = _dir(k)
        for i in range(nx):
            for j in range(ny):
                q = Q[k, i, j]
                if q > 0.0:
                    Q[k, i, j] = q * out[i, j]
                elif q < 0.0:
                    Q[k, i, j] = q * out[i + di, j + dj]
    for i in range(nx):
        for j in range(ny):
            rate[i, j] = V[i, j]
    for k in range(4):
        di, dj = _dir(k)
        for i in range(nx):
            for j in range(ny):
                f = dt * Q[k, i, j]
                if f != 0.0:
                    V[i, j] -= f
                    V[i + di, j + dj] += f
    inv = 1.0 / (area * dt)
    for i in range(nx):
        for j in range(ny):
            rate[i, j] = (V[i, j] - rate[i, j]) * inv


@njit(cache=True)
def _surface_velocity(px, py, grid, state):
    """The surface's velocity (m/s) at (px, py): bilinear over the four nearest fluid
    columns of their flow velocity and the surface's vertical speed."""
    x0, y0, l, fluid, pipe, area, w = grid.x0, grid.y0, grid.l, grid.fluid, grid.pipe, grid.area, grid.w
    Q, V, rate = state.Q, state.V, state.rate
    nx, ny = V.shape
    fx = (px - x0) / l
    fy = (py - y0) / l
    i0 = min(max(int(math.floor(fx)), 0), nx - 2)
    j0 = min(max(int(math.floor(fy)), 0), ny - 2)
    tx = min(max(fx - i0, 0.0), 1.0)
    ty = min(max(fy - j0, 0.0), 1.0)
    sx = sy = sz = wsum = 0.0
    for a in range(2):
        for b in range(2):
            if fluid[i0 + a, j0 + b]:
                wt = (tx if a else 1.0 - tx) * (ty if b else 1.0 - ty)
                u, v = column_velocity(Q, V, pipe, i0 + a, j0 + b, area, w)
                sx += wt * u
                sy += wt * v
                sz += wt * rate[i0 + a, j0 + b]
                wsum += wt
    if wsum <= 0.0:
        return 0.0, 0.0, 0.0
    return sx / wsum, sy / wsum, sz / wsum


@njit(cache=True)
def emit_spray(grid, state, settings, H, count, dt):
    """Emit particles where the surface rises faster than ``threshold`` (m/s): the expected
    number from a column is fraction * l^2 (rate - threshold) dt / vp, rounded stochastically,
    placed uniformly over the column at its surface with the surface's interpolated velocity.
    Each particle's volume vp (m^3, radius m) leaves its column; columns shallower than four
    radii do not spray. Counts the particles into state.track[EMITTED]. Returns the new
    particle count."""
    fluid, area, l, x0, y0 = grid.fluid, grid.area, grid.l, grid.x0, grid.y0
    V, rate, px, pv, track = state.V, state.rate, state.px, state.pv, state.track
    threshold, fraction, vp, radius = (settings.threshold, settings.fraction, settings.vp,
                                       settings.radius)
    nx, ny = V.shape
    cap = px.shape[0]
    n = count
    for i in range(nx):
        for j in range(ny):
            r = rate[i, j]
            # a film a few drops deep (a wetting beach) flickers fast but has nothing to throw
            if r <= threshold or not fluid[i, j] \
                    or V[i, j] / area < 4.0 * radius:
                continue
            if n >= cap:
                return n
            k = int(fraction * area * (r - threshold) * dt / vp + np.random.random())
            k = min(k, int(V[i, j] * _KEEP / vp), cap - n)  # never below empty
            track[EMITTED] += k
            for _ in range(k):
                x = x0 + (i + np.random.random() - 0.5) * l
                y = y0 + (j + np.random.random() - 0.5) * l
                px[n, 0] = x
                px[n, 1] = y
                px[n, 2] = H[i, j]
                pv[n, 0], pv[n, 1], pv[n, 2] = _surface_velocity(x, y, grid, state)
                V[i, j] -= vp
                n += 1
    return n


@njit(cache=True, inline="always")
def _land(V, fluid, i, j, vp):
    """Return a landed particle's volume vp to column (i, j) and its fluid neighbours
    (weights 4 / 2 / 1 for centre / side / corner): a drop's volume in one column would be a
    one-column bump whose collapse rises faster than the spray threshold and sprays again."""
    nx, ny = V.shape
    wsum = 0.0
    for a in range(max(i - 1, 0), min(i + 2, nx)):
        for b in range(max(j - 1, 0), min(j + 2, ny)):
            if fluid[a, b]:
                wsum += 4.0 / ((1 + abs(a - i)) * (1 + abs(b - j)))
    left = vp
    for a in range(max(i - 1, 0), min(i + 2, nx)):
        for b in range(max(j - 1, 0), min(j + 2, ny)):
            if fluid[a, b] and not (a == i and b == j):
                part = vp * 4.0 / ((1 + abs(a - i)) * (1 + abs(b - j))) / wsum
                V[a, b] += part
                left -= part
    V[i, j] += left  # the remainder, so exactly vp is returned


@njit(cache=True)
def move_spray(grid, state, settings, H, count, dt):
    """Ballistic flight with quadratic air drag (a = g - drag |v| v, drag in 1/m). A particle
    that falls to the surface (or onto a wall) gives its volume back around the fluid column
    below it (the nearest fluid column, off the water). The highest particle goes into
    state.track[HIGHEST]. Returns the new count."""
    fluid, bed, nearest, x0, y0, l = grid.fluid, grid.bed, grid.nearest, grid.x0, grid.y0, grid.l
    V, px, pv, track = state.V, state.px, state.pv, state.track
    g, drag, vp = settings.g, settings.drag, settings.vp
    nx, ny = V.shape
    n = count
    p = 0
    while p < n:
        sp = math.sqrt(pv[p, 0] ** 2 + pv[p, 1] ** 2 + pv[p, 2] ** 2)
        pv[p, 0] -= dt * drag * sp * pv[p, 0]
        pv[p, 1] -= dt * drag * sp * pv[p, 1]
        pv[p, 2] += dt * (-g - drag * sp * pv[p, 2])
        for c in range(3):
            px[p, c] += dt * pv[p, c]
        if px[p, 2] > track[HIGHEST]:
            track[HIGHEST] = px[p, 2]
        i = min(max(int(math.floor((px[p, 0] - x0) / l + 0.5)), 0), nx - 1)
        j = min(max(int(math.floor((px[p, 1] - y0) / l + 0.5)), 0), ny - 1)
        ground = H[i, j] if fluid[i, j] else bed[i, j]
        if pv[p, 2] < 0.0 and px[p, 2] <= ground:
            t = nearest[i, j]
            _land(V, fluid, t // ny, t % ny, vp)
            n -= 1
            for c in range(3):
                px[p, c] = px[n, c]
                pv[p, c] = pv[n, c]
        else:
            p += 1
    return n


@njit(cache=True)
def advance(grid, state, lids, n_lid, settings, scratch, count, seed, h, dt_max):
    """Advance the water h seconds in equal substeps no longer than dt_max or the wave-speed
    limit cfl * l / sqrt(g d_max (1 + kappa if bodies touch it)), rechecked each coupling
    step; the bodies' first n_lid lids move on at their vertical speeds (a lid held still for
    the step and jumping at its end would hit the water with pressure spikes of kappa v h).
    count: airborne particles; seed: the spray's random seed for this call. state.track is
    updated in place. Returns (particle count, substeps)."""
    V, fluid, area, l = state.V, grid.fluid, grid.area, grid.l
    g, kappa, cfl = settings.g, settings.kappa, settings.cfl
    lid_zlo, lid_zhi, lid_vz = lids.zlo, lids.zhi, lids.vz
    track = state.track
    dmax = max_depth(V, fluid, area)
    stiff = 1.0 + kappa if n_lid > 0 else 1.0
    lim = cfl * l / math.sqrt(g * dmax * stiff) if dmax > 0.0 else dt_max
    nsub = max(1, int(math.ceil(h / min(dt_max, lim) - 1e-9)))
    dt = h / nsub
    np.random.seed(seed)  # counter-based seeding: a rerun from a capture repeats the spray
    nx, ny = V.shape
    for _ in range(nsub):
        flow_step(grid, state, lids, n_lid, settings, scratch, dt)
        if settings.spray:  # H is the substep's start: spray leaves and lands on it
            count = emit_spray(grid, state, settings, scratch.H, count, dt)
            count = move_spray(grid, state, settings, scratch.H, count, dt)
        for k in range(n_lid):  # the bodies move on within the coupling step
            for s in range(lid_zlo.shape[1]):
                lid_zlo[k, s] += lid_vz[k] * dt
                lid_zhi[k, s] += lid_vz[k] * dt
        if count > track[PEAK]:
            track[PEAK] = count
    for i in range(nx):
        for j in range(ny):
            if fluid[i, j] and V[i, j] / area < track[MIN_DEPTH]:
                track[MIN_DEPTH] = V[i, j] / area
    return count, nsub


@njit(cache=True)
def energy_momentum(grid, state, rho, count, vp, out):
    """Kinetic energy (J) and horizontal momentum (kg m/s) of the columns (from their flow
    velocities) plus the vertical too for airborne particles: out = [E, px, py, pz]; rho
    (kg/m^3), count airborne particles of volume vp (m^3)."""
    pipe, fluid, area, w = grid.pipe, grid.fluid, grid.area, grid.w
    V, Q, pv = state.V, state.Q, state.pv
    nx, ny = V.shape
    e = 0.0
    mx = 0.0
    my = 0.0
    mz = 0.0
    for i in range(nx):
        for j in range(ny):
            if fluid[i, j] and V[i, j] > 0.0:
                u, v = column_velocity(Q, V, pipe, i, j, area, w)
                m = rho * V[i, j]
                e += 0.5 * m * (u * u + v * v)
                mx += m * u
                my += m * v
    mp = rho * vp
    for p in range(count):
        e += 0.5 * mp * (pv[p, 0] ** 2 + pv[p, 1] ** 2 + pv[p, 2] ** 2)
        mx += mp * pv[p, 0]
        my += mp * pv[p, 1]
        mz += mp * pv[p, 2]
    out[0] = e
    out[1] = mx
    out[2] = my
    out[3] = mz


@njit(cache=True)
def solid_loads(grid, state, lids, n_lid, o0, o1, kappa, out):
    """What the water does to solids o0..o1-1 (owners of lids): out (o1 - o0, 7) = [displaced
    volume (m^3: head kept out times column area, so rho g out[0] is the force), centre of
    buoyancy (3) m, water velocity (3) m/s]. Where several solids share a sample, the water
    the column's head keeps out is given to them bottom up (each gets what is left above the
    chords of the solids below it, up to its own chord), so the solids together carry exactly
    the pressure the water bears. The velocity is load-weighted: horizontal from the column's
    flows, vertical the surface's rise scaled by the height above the bed."""
    pipe, bed, area, x0, y0, l, w = grid.pipe, grid.bed, grid.area, grid.x0, grid.y0, grid.l, grid.w
    V, Q, rate = state.V, state.Q, state.rate
    cell, owner, zlo, zhi, scale = lids.cell, lids.owner, lids.zlo, lids.zhi, lids.scale
    nx, ny = V.shape
    ns2 = zlo.shape[1]
    ns = int(round(math.sqrt(ns2)))
    out[:, :] = 0.0
    k = 0
    while k < n_lid:
        k1 = run_end(cell, k, n_lid)
        mine = False
        for m in range(k, k1):
            mine = mine or o0 <= owner[m] < o1
        if not mine:
            k = k1
            continue
        i, j = cell[k] // ny, cell[k] % ny
        b = bed[i, j]
        H = column_level(b + V[i, j] / area, b, lids, k, k1, kappa)
        u, v = column_velocity(Q, V, pipe, i, j, area, w)
        for s in range(ns2):
            lo, ch = merged(lids, k, k1, s, b)
            if ch <= 0.0:
                continue
            c, _ = content(H, b, lo, ch, kappa)
            head = H - b - c  # what the bodies keep out of this sample (m)
            if head <= 0.0:
                continue
            x = x0 + (i - 0.5 + (s // ns + 0.5) / ns) * l
            y = y0 + (j - 0.5 + (s % ns + 0.5) / ns) * l
            for m in range(k, k1):
                if not o0 <= owner[m] < o1:
                    continue
                lm, cm = lid_sample(zlo[m, s], zhi[m, s], scale[m], b)
                if cm <= 0.0:
                    continue
                below = 0.0
                for q in range(k, k1):
                    lq, cq = lid_sample(zlo[q, s], zhi[q, s], scale[q], b)
                    if cq > 0.0 and (lq < lm or (lq == lm and q < m)):
                        below += cq
                share = min(max(head - below, 0.0), cm)
                if share <= 0.0:
                    continue
                dv = share * area / ns2
                zc = lm + 0.5 * share
                r = out[owner[m] - o0]
                r[0] += dv
                r[1] += dv * x
                r[2] += dv * y
                r[3] += dv * zc
                r[4] += dv * u
                r[5] += dv * v
                # shallow water: the vertical velocity grows linearly from the bed up
                r[6] += dv * rate[i, j] * min(max((zc - b) / max(H - b, 1e-9), 0.0), 1.0)
        k = k1
    for o in range(o1 - o0):
        if out[o, 0] > 0.0:
            for q in range(1, 7):
                out[o, q] /= out[o, 0]

"""The contact law (SPEC 2.5 response), written once: every contact in Interplay calls it.

At a contact point with penetration p (m), separating normal velocity pdot = v_rel . n (m/s),
relative acceleration a_n = a_rel . n from every other force (m/s^2) and the pair's inverse
effective mass 1/m_eff along n (1/kg):

* normal force f_n = c_s p - c_d pdot + f_c, where the constraint term f_c = -m_eff min(0, a_n)
  cancels the acceleration pushing the two together (so a resting load is carried without
  sinking); a contact pushes, never pulls (f_n <= 0 means no contact);
* friction: regularised Coulomb, |f_t| = mu f_n min(1, |v_t| / eps) against the slip v_t,
  capped at m_eff |v_t| / dt, the force that stops the slip within the step the force is held
  for (without the cap, the viscous range mu f_n / eps on a fraction-of-a-gram net knot would
  make explicit steps chatter); or, where a contact must hold a load on a slope, sticking
  through a tangential spring (``sticking_friction``).

The functions are scalar and inlined, so each caller keeps its own loop and memory layout
while the arithmetic is the same everywhere. Units are SI; n points from the other body to
the side the force acts on.
"""
import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def normal_force(pen, vn, an, inv_m, cs, cd, constraint):
    """f_n (N) = c_s pen - c_d vn, plus the constraint term -a_n m_eff when a_n < 0 and
    ``constraint``; the caller treats f_n <= 0 as no contact. pen (m), vn (m/s, separating),
    an (m/s^2), inv_m (1/kg), c_s (N/m), c_d (N s/m)."""
    fn = cs * pen - cd * vn
    if constraint and an < 0.0:
        fn += -an / inv_m
    return fn


@njit(cache=True, inline="always")
def sliding_friction(fn, vtn, mu, eps, inv_m, dt):
    """Magnitude (N) of the regularised Coulomb friction against a slip of speed vtn (m/s):
    mu f_n min(1, vtn / eps), capped at vtn / (inv_m dt) when dt > 0 (s)."""
    fmag = mu * fn * min(1.0, vtn / eps)
    if dt > 0.0:
        fmag = min(fmag, vtn / (inv_m * dt))
    return fmag


@njit(cache=True, inline="always")
def friction_damping(fn, vtn, mu, eps, inv_m, dt):
    """The regularised law as a damper (N s/m): the secant mu f_n / max(vtn, eps), its
    force -visc v_t (points_on_plane), capped at m_eff / dt when dt > 0."""
    visc = mu * fn / max(vtn, eps)
    if dt > 0.0:
        visc = min(visc, 1.0 / (inv_m * dt))
    return visc


@njit(cache=True, inline="always")
def friction_slope(fn, vtn, mu, eps, inv_m, dt):
    """The friction's velocity Jacobian coefficient (N s/m) in the tangent plane, for implicit
    integrators: the regularised law's slope mu f_n / eps where it is linear (vtn < eps) and
    not capped; 0 where it slides or is capped, its force held over the step (the cap keeps
    a held force from reversing the slip). A secant there, mu f_n / vtn, would weaken a
    sliding contact's friction on a light point by 1 / (1 + mu f_n dt inv_m / vtn): with it
    the basketball's implicit net did not converge to its reference (3 cm off at 1e-4 s).
    The sphere contact uses it; the rigid parts' contact (kernels/part_contact.py) keeps the
    secant: with the slope the owl-creek noose's peak fell from 5.3 kN to 0.46 kN, a change
    of that scene's physics not yet understood."""
    if vtn >= eps or (dt > 0.0 and mu * fn / eps > 1.0 / (inv_m * dt)):
        return 0.0
    return mu * fn / eps


@njit(cache=True, inline="always")
def backward_euler_normal(pen, vn, m, h, cs, cd):
    """The normal velocity change (m/s, >= 0) of a point of mass m (kg) at the end of a step of
    h (s) against a surface that does not give way, such that the law's force at the step's
    end, c_s (pen - h dv) - c_d (vn + dv), is what changed its velocity by dv: backward Euler
    on the contact alone (pen m and vn m/s at the step's end before the contact acts). As
    c_s h^2 / m grows it becomes the projection onto the surface."""
    dv = (cs * pen - cd * vn) / (m / h + cs * h + cd)
    return dv if dv > 0.0 else 0.0


@njit(cache=True)
def sticking_friction(n, vt, fn, cs, cd, mu, eps, meff, dt, stretch, out_ft):
    """Coulomb friction that sticks: a tangential spring from where the contact first held
    (``stretch``, m, the spring's extension, kept by the caller per contact and updated here),
    with the normal's stiffness c_s (N/m) and damping c_d (N s/m), saturating at the cone
    mu f_n. The regularised law's viscous range would let a loaded contact creep at
    ~eps tan(theta) / mu on a slope it should stick to; the spring holds it. Writes the
    tangential force (N) into out_ft and returns (stick stiffness N/m, tangential damping
    N s/m) for the Jacobians."""
    vtn = np.sqrt(vt @ vt)
    cap = mu * fn
    u = stretch - (stretch @ n) * n + dt * vt
    g = cs * u + cd * vt
    gn = np.sqrt(g @ g)
    if gn <= cap:
        for a in range(3):
            out_ft[a] = -g[a]
        for a in range(3):
            stretch[a] = u[a]
        return cs, cd
    # slipping: Coulomb at the cone, opposing the spring and the slip; below eps the spring,
    # saturated here, takes the place of the regularised law's viscous range
    for a in range(3):
        out_ft[a] = -cap / gn * g[a]
    visc = 0.0
    if vtn < eps:
        visc = min(cap / eps, meff / dt) if dt > 0.0 else cap / eps
    if cs > 0.0:
        for a in range(3):
            stretch[a] = g[a] * (cap / (gn * cs))  # the spring at its limit
    else:
        stretch[:] = 0.0
    return 0.0, visc

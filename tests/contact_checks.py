"""Checks shared by the contact tests of several scenes."""
import numpy as np


def contact_step(fig, net, contact, h):
    """The contact's part of one coupling step of h as the scheduler takes it: forces
    cleared, the exchange, the network advanced with the contact sub-cycled in it, the step
    completed; the figure is left to advance. Returns the contact's result (force, torque,
    touching[, peak])."""
    fig.clear_forces()
    net.clear_forces()
    res = contact.exchange(True, True)
    net.advance(h, net.dt)
    return contact.complete(True) if res is None else res


def equal_and_opposite_every_step(scene, network, h, steps):
    """Step the scene's first interaction (a sub-cycled rigid-parts contact) and its two
    systems by hand for ``steps`` coupling steps of h: at every step the impulse the network's
    points received is minus the impulse the parts received (to round-off), and what the
    figure is given is that impulse over the step. Returns the steps in contact."""
    fig, net = scene.primary, next(s for s in scene.systems if s.name == network)
    contact = scene.interactions[0]
    contact.prepare(h, {net.name: net.dt, fig.name: fig.dt})
    touched = 0
    for _ in range(steps):
        res = contact_step(fig, net, contact, h)
        P = contact.parts
        given = P.impulses[:, :3].sum(axis=0)
        scale = max(np.abs(given).max(), 1e-9)
        assert np.allclose(P.received, -given, atol=1e-9 * scale)
        if res[2]:
            touched += 1
            assert np.allclose(fig.segment_wrenches()[:, :3].sum(axis=0), given / h,
                               atol=1e-9 * scale / h)
        fig.advance(h)
    return touched

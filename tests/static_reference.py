"""A slow reference shared by the load tests of several networks: a spring network's rest
under fixed loads as the minimum of its potential energy."""
import numpy as np
from scipy.optimize import minimize


def rest_under_load(net, f, free, gtol, ftol):
    """The positions (n,3) m at which the network's springs (slack tension-only ones
    carrying nothing) balance the forces f (n,3) N on its ``free`` points, the others held,
    by L-BFGS on the potential energy from its current positions; and the largest residual
    force (N) left."""
    x0 = net.x.copy()

    def energy(u):
        x = x0.copy()
        x[free] = u.reshape(-1, 3)
        d = x[net.si] - x[net.sj]
        ln = np.linalg.norm(d, axis=1)
        e = ln - net.l0
        e[net.tension_only & (e < 0)] = 0.0
        g = (net.k * e / ln)[:, None] * d
        grad = np.zeros_like(x)
        np.add.at(grad, net.si, g)
        np.add.at(grad, net.sj, -g)
        grad -= f
        return 0.5 * float(net.k @ (e * e)) - float((f * x).sum()), grad[free].ravel()
    res = minimize(energy, x0[free].ravel(), jac=True, method="L-BFGS-B",
                   options={"maxiter": 20000, "gtol": gtol, "ftol": ftol, "maxcor": 30})
    x = x0.copy()
    x[free] = res.x.reshape(-1, 3)
    return x, np.abs(res.jac).max()

"""The mat's support under a standing gymnast against the stand-in's (issue 17's two-way
sideways drift, docs/mat.md): both soles (two feet side by side, |x| <= 0.125 m,
0.033 <= |y| <= 0.127 m) pressed as one rigid plate to the standing depth D0, then tilted
by theta about the x axis (roll stiffness, N m/rad: the moment over theta) and shifted sideways
(shear stiffness, N/m); the stand-in's roll stiffness from its law at the feet's box corners.
Her toppling stiffness on a rigid base is m g h (h: her centre of mass over the soles).
Prints the figures; nothing is timed.

    PYTHONPATH=src python benchmarks/mat_support.py
"""
import numpy as np

from interplay.scenes import mat as M
from interplay.systems.relaxation import relax

D0 = 0.0085  # m: the depth at which the soles carry her weight (~570 N on the mat)
CORNERS_Y = np.array([0.033, 0.033, 0.127, 0.127, -0.033, -0.033, -0.127, -0.127])


def held(net, sel, depth, dy=0.0):
    """The forces (n,3) N the held sole points ``sel`` carry, lowered by ``depth`` (m, per
    point) and shifted by dy (m) sideways, the rest of the mat relaxed; the mat left as it was."""
    x0, fixed = net.x.copy(), net.fixed.copy()
    net.fixed[net.bottom] = True
    net.fixed[sel] = True

    def move(k, n):
        s = min(1.0, 2.0 * (k + 1) / n)
        net.x[sel, 2] = x0[sel, 2] - depth * s
        net.x[sel, 1] = x0[sel, 1] + dy * s
    relax(net, 0.4, 1e-2, 100.0, 4000, move)
    f = net.internal_forces()[sel]
    net.x[:], net.fixed[:] = x0, fixed
    return f


def main():
    p = M.MatSceneParams()
    net = M.mat_network(p.mat, "implicit")
    top = net.x[net.top]
    rel = top - 0.5 * (top.min(axis=0) + top.max(axis=0))
    sole = ((np.abs(rel[:, 0]) <= 0.125) & (np.abs(rel[:, 1]) >= 0.033)
            & (np.abs(rel[:, 1]) <= 0.127))
    sel, ys = net.top[sole], rel[sole, 1]
    print(f"{len(sel)} top points under the soles; at D0 = {D0} m they carry "
          f"{held(net, sel, np.full(len(sel), D0))[:, 2].sum():.0f} N")
    st = p.standin
    for th in (0.02, 0.05):
        m_mat = float((held(net, sel, D0 + th * ys)[:, 2] * ys).sum())
        d = D0 + th * CORNERS_Y
        deep = d.max()
        on = d > deep - st.pocket
        w = d[on] - (deep - st.pocket)
        share = st.force(deep) * w / w.sum()
        m_st = float((share * CORNERS_Y[on]).sum())
        print(f"roll {th} rad: mat {m_mat / th:.0f} N m/rad, stand-in {m_st / th:.0f} N m/rad "
              f"(its load {st.force(deep):.0f} N)")
    for dy in (0.005, 0.01):
        f = held(net, sel, np.full(len(sel), D0), dy)
        print(f"shear {dy} m: mat {-f[:, 1].sum() / dy:.0f} N/m")
    print(f"m g h at h = 0.9 m: {64.38 * 9.81 * 0.9:.0f} N m/rad")


if __name__ == "__main__":
    main()

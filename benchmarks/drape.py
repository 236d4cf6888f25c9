"""The cloth drape benchmark's scene, shared by bench_cloth.py and its peers: a 1 m square
cloth of n x n points, flat at HEIGHT over a fixed sphere at the origin, pinned at the two
corners of its first row (points 0 and n - 1), falls under gravity for DURATION."""
DURATION = 2.0  # s
RADIUS = 0.25  # m, sphere at the origin
HEIGHT = 0.35  # m, the cloth starts flat this high, centred over the sphere
DENSITY = 0.15  # kg/m^2, cotton
STRETCH = 200.0  # N, springs k = STRETCH / l0: cotton-like (the flags' cotton is 150 N)
THICKNESS, CONTACT_KE, CONTACT_KD, MU = 0.005, 2.0e3, 0.01, 0.3  # m, N/m, N s/m, -
FRAME = 1.0 / 60.0  # s, the coupling step (forces and the sphere are exchanged this often)

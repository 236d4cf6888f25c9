"""Headless preview rendering: moderngl on EGL (CPU), H.264 MP4 through imageio-ffmpeg.

camera.py   --camera specs and the default framing
gl.py       the Renderer (lit meshes, cords as tubes, soft shadows, MSAA)
shaders.py  its GLSL
overlay.py  scene, coupling mode and time in a corner
video.py    MP4 of one run; several runs side by side
"""

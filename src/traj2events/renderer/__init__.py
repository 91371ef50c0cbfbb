"""Rendering: the scene drawn as linear radiance and depth per camera pose, through OpenGL
(docs/rendering.md).

Read first:
    draw           the terrain renderer: one instanced draw of the chosen tiles per frame
    shaders/       the GLSL that evaluates reflectance and depth per pixel

Machinery a reader may skip:
    context        the OpenGL backend (EGL or OSMesa) and a headless context of it
"""

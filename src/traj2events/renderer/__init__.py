"""Rendering: the scene drawn as linear radiance and depth per camera pose, through OpenGL
(docs/rendering.md).

Read first:
    draw           the terrain renderer: one instanced draw of the chosen tiles per frame
    shaders/       the GLSL that evaluates reflectance and depth per pixel

Machinery a reader may skip:
    context        the OpenGL backend (EGL or OSMesa) and a headless context of it
    glsl           the shaders' sources (includes, defines) compiled into programs; uniforms
    camera_matrices  the pinhole camera's OpenGL projection and view matrices
    law_uniforms   the reflectance laws' parameters as the shaders take them
    footprint      a pixel's footprint on the shading texture (its levels, the box filter)
    shading_array  the texture array of shading textures, one tile per layer
    lens           a distorting lens: a pinhole cover drawn, then resampled onto the sensor
    supersample    S x S supersampling, the pixel footprint's reference
"""

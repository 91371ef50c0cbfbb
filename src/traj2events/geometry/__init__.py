"""Geometry: the camera and what it sees move (docs/geometry.md).

Read first (the model):
    camera         the pinhole camera, its mounting and poses, frame conventions
    distortion     the lens's radial-tangential distortion (OpenCV's model) and its inverse
    motion_field   the motion field's equations in numpy: flow, exact displacement, status
    range_meter    ELOPE's range meter: the slant range read at a fixed rate
    horizon        how far a camera sees over the sphere (plain floats: the DAG computes it)

Machinery a reader may skip:
    motion_pass    the same motion field in one compiled pass per field (numba), bit for bit
    frame_timing   when to render: fixed rate, or adaptive from the predicted log change
"""

"""The scene: the lunar surface, its light and the sky (docs/rendering.md). Nothing here
knows of OpenGL; `renderer` draws what these modules describe.

Read first (the model):
    terrain        procedural heights: craters, boulders, a DEM when given
    sun            the Sun: direction and irradiance
    illumination   horizon-march shadows under it
    reflectance    the Hapke law (the shaders evaluate the same law)
    stars          the star field seen in the sky

Machinery a reader may skip:
    terrain_kernels  the terrain's compiled hashing, feature lookup and value noise
    tiles          level of detail: a quadtree of terrain tiles chosen per frame, cached
"""

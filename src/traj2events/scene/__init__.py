"""The scene: the lunar surface, its light and the sky (docs/rendering.md). Nothing here
knows of OpenGL; `renderer` draws what these modules describe.

Read first (the model):
    terrain        procedural heights: craters, boulders, a DEM when given
    dem            a real site: a DEM product's heights placed on the site's frame
    sun            the Sun: direction and irradiance
    ephemeris      the Sun of a date at a real site, from SPICE kernels
    illumination   horizon-march shadows under it
    reflectance    the Hapke law (the shaders evaluate the same law)
    stars          the star field seen in the sky
    earthshine     sunlight the Earth reflects onto the Moon, an optional second light
    scattering     sunlight scattered into shadows: one bounce off the sunlit terrain

Machinery a reader may skip:
    terrain_kernels  the terrain's compiled hashing, feature lookup and value noise
    tiles          level of detail: a quadtree of terrain tiles chosen per frame, cached
    populations    features drawn from cumulative power laws of size, octave by octave
    sky_cells      the sky cut into cells of equal area, so a frame projects its own stars
    view           the view frustum, how far terrain is seen, the depth range drawn
"""

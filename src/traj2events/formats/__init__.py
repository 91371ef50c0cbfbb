"""File formats, with numpy and h5py (+ hdf5plugin for events and motion fields) only: reading any output
of the pipeline never loads the solver or the renderer.

    atomic      one helper for every write: a temporary name, renamed when complete
    hdf5        byte-reproducible HDF5 files, datasets and attributes
    units       every dataset's units (CF / UDUNITS) and categories, one table per kind of file
    trajectory  base.h5, solutions.h5, trajectory.h5 (nodes, poses, vehicle constants)
    frames      frames.h5 (linear radiance and depth per frame)
    rounding    frames.h5's mantissa rounding, compiled (numba: for writing only)
    flow        motion_field.h5 and Middlebury .flo
    events      the event dtype and events.h5 (DSEC layout)
    exports     the ELOPE-style .npz, EVT 3.0 and AEDAT4
    imu         imu.h5: one trajectory's inertial and altitude streams
    poses       pose files (CSV, HDF5, trajectory.h5) read into the site frame
    spice       camera poses from SPICE kernels (the `spice` extra)
    tile_cache  the render's cache of tile heights, shared between jobs
"""

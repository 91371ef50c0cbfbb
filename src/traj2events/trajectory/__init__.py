"""Trajectories: the lander's dynamics and its mass-optimal landings (docs/trajectories.md).

Read first (the model):
    state          named state and control rows, units, the attitude convention
    dynamics       the equations of motion, as the paper writes them
    ocp            the optimal-control problem (Hermite-Simpson, CasADi Opti, IPOPT)
    scenarios      boundary-condition ranges, seeded sampling, continuation from the base
    upsample       poses at the frame rate: the dynamics re-integrated under the optimal controls
    flight         a trajectory.h5's flight at any time, whatever made it
    legs           a leg of a flight: from a state to rest upright over a point
    divert         diverts: the site moves mid-flight and the rest is re-solved
    hover          hover and hazard avoidance: hold over a point, then land at the site
    external       a flight given as time-stamped camera poses, interpolated
    imu            what an IMU at the centre of mass measures, noise-free; the altitude

Machinery a reader may skip:
    batch          samples solved one process per core, in rounds
    motion_stats   summary figures of how a trajectory moves (used to choose the ranges)
"""

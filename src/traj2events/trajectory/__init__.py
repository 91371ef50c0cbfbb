"""Trajectories: the lander's dynamics and its mass-optimal landings (docs/trajectories.md).

Read first (the model):
    state          named state and control rows, units, the attitude convention
    vehicle        the lander's constants
    dynamics       the equations of motion, as the paper writes them
    ocp            the optimal-control problem (Hermite-Simpson, CasADi Opti, IPOPT)
    scenarios      boundary-condition ranges, seeded sampling, continuation from the base
    upsample       poses at the frame rate: the dynamics re-integrated under the optimal controls

Machinery a reader may skip:
    batch          samples solved one process per core, in rounds
    motion_stats   summary figures of how a trajectory moves (used to choose the ranges)
"""

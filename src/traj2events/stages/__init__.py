"""One module per workflow rule: read input files, call the science, write output files.
The command line (cli.py), the tests and the benchmarks all call these functions.

    base_solution         the scenario's base optimal-control solve          -> base.h5
    sample_trajectories   continuation sampling of the boundary conditions   -> solutions.h5, samples.csv
    camera_poses          poses at the frame rate from the re-integrated dynamics -> trajectory.h5
    external_poses        an external scenario's poses from a pose file or SPICE -> trajectory.h5
    imu                   the IMU and altitude streams at the IMU's rate     -> imu.h5
    render                linear radiance, depth and videos of every pose    -> frames.h5, video.mkv, preview.mp4
    motion_field          ground-truth motion field of every n-th frame      -> motion_field.h5, flow/*.flo
    events                event emulation                                    -> events.h5
    render_events         render and events in one job, frames in memory     -> the files of both (frames.h5: depth)
    export                a built trajectory's events, poses and IMU in other formats -> .npz, .raw, .aedat4, .mp4,
                          TUM, EuRoC (`traj2events export`, the export_events jobs)
    pictures              mosaics of frames, motion field and events; the dataset figure (PNG)
    index                 one row per trajectory of a scenario               -> index.csv
    summary               one row per scenario                               -> summary.csv
    overview              the dataset in numbers and figures                 -> overview.html
"""

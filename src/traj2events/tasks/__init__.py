"""Tasks, metrics and baselines over a built dataset (docs/tasks.md): the inverse problems
the data is for, each scored against its ground truth by `traj2events score`.

    poses          what every task reads of a landing: its flight, camera, scored poses
    flow           (a) optical flow: EPE and 3 px outliers against the terrain's displacement
    divergence     (b) divergence and time to contact (McLeod et al. 2022)
    egomotion      (c) velocity and body rates, scored by ELOPE's metric
    landing_site   (d) the touchdown point's pixel
    predictions    the prediction CSVs, read and checked before scoring
    score          a prediction file against the dataset -> scores/{task}-{name}.csv, .png
    affine_flow    the affine radial flow model of the divergence baselines
    contrast_max   contrast maximisation of the events (Gallego et al. 2018)
    frame_flow     OpenCV's DIS flow on video.mkv, and its divergence
    strapdown      the IMU dead-reckoned: the egomotion an IMU alone gives
    baselines      truth, trivial predictors, cmax and dis -> prediction files
    commands       the `score` and `baseline` subcommands
"""

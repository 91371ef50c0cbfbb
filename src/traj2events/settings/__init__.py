"""What each stage's jobs depend on, built from the validated config: the one channel from
the config to the stages (the workflow's `params`, the commands' `--settings`). Plain
values only, importable without CasADi or numba, so that the workflow builds its DAG
without loading the solver or the kernels. One module per stage, so that editing one
stage's settings reruns only that stage (a module's fingerprint covers what it imports):

    solve     base and sample solves of a scenario: vehicle, ocp, ranges, seed
    render    one scenario's frames: camera, terrain, Sun, reflectance, detail, timing
    events    the emulation: pixel-model preset and overrides, labels, input, sensor
    camera    the camera and the Moon's sphere (motion field, its picture)

Each stage turns its settings into its model's objects (`trajectory.scenarios.ScenarioSettings`,
`stages.render.RenderSettings`, `sensor.emulator.EmulatorParams`, `geometry.camera.Camera`).
"""

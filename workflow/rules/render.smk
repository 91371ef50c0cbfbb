# Stages 4-5: render the lunar surface from every pose (linear radiance + depth), and the
# videos (lossless FFV1; an H.264 preview unless render.preview is false) made from the same frames.
# With render.keep_frames false, the same job emulates the events (stage 7) from the frames
# in memory: an emulator setting then reruns it.


rule render:
    input:
        trajectory="results/{scenario}/{id}/trajectory.h5",
        dem=elevation_grid,
    output:
        **render_outputs("results/{scenario}/{id}"),
    log:
        "results/logs/{scenario}/{id}/render.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/render.tsv"
    conda:
        "../../envs/render.yaml"
    threads: 1
    resources:
        mem_mb=resources_of("render_events" if ONE_JOB else "render", "mem_mb"),
        runtime=resources_of("render_events" if ONE_JOB else "render", "runtime"),
    params:
        settings=settings("render"),
        code=code("render_events" if ONE_JOB else "render"),
        events_settings=settings("events") if ONE_JOB else "",
        seed=trajectory_seed if ONE_JOB else "",
        events=events_in_render,
        backend=config["render"]["backend"],
        tile_cache=tile_cache_option,
        preview=preview_option,
    shell:
        # llvmpipe would start a thread per core in every job; one job = one core.
        "LP_NUM_THREADS={threads} traj2events render {input.trajectory} --settings '{params.settings}' "
        "--frames {output.frames} --video {output.video} {params.preview} --backend {params.backend} {params.tile_cache} "
        "{params.events} 2> {log}"

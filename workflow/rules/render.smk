# Stages 4-5: render the lunar surface from every pose (linear radiance + depth), and the
# videos (lossless FFV1; an H.264 preview unless render.preview is false) made from the same frames.


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
        mem_mb=resources_of("render", "mem_mb"),
        runtime=resources_of("render", "runtime"),
    params:
        settings=render_settings,
        code=code("render"),
        backend=config["render"]["backend"],
        tile_cache=tile_cache_option,
        preview=preview_option,
    shell:
        # llvmpipe would start a thread per core in every job; one job = one core.
        "LP_NUM_THREADS={threads} traj2events render {input.trajectory} --settings '{params.settings}' "
        "--frames {output.frames} --video {output.video} {params.preview} --backend {params.backend} {params.tile_cache} 2> {log}"

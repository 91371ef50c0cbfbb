# Stage 7: event emulation per trajectory, from the rendered linear radiance (the HDR
# path), with the exports the config asks for. Its own job when frames.h5 is kept (an
# emulator setting then reruns this job only); else the render job does it (render.smk).


if not ONE_JOB:

    rule events:
        input:
            frames="results/{scenario}/{id}/frames.h5",
            trajectory="results/{scenario}/{id}/trajectory.h5",
        output:
            **export_outputs("results/{scenario}/{id}"),
            events="results/{scenario}/{id}/events.h5",
        log:
            "results/logs/{scenario}/{id}/events.log",
        benchmark:
            "results/benchmarks/{scenario}/{id}/events.tsv"
        conda:
            ENV
        # One core per job: many jobs side by side use the cores better than threads within one.
        threads: 1
        resources:
            mem_mb=resources_of("events", "mem_mb"),
            runtime=resources_of("events", "runtime"),
        params:
            settings=settings("events"),
            seed=trajectory_seed,
            exports=export_flags,
            code=code("events"),
        shell:
            "traj2events events {input.frames} --output {output.events} --seed {params.seed} --settings {params.settings:q} "
            "--trajectory {input.trajectory} {params.exports} --threads {threads} 2> {log}"

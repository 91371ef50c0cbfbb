# Stage 7: event emulation per trajectory, from the rendered linear radiance (the HDR
# path). Its own job when frames.h5 is kept (an emulator setting then reruns this job
# only); else the render job does it (render.smk). Each export the config asks for is a job
# of its own, from events.h5: adding one to a built dataset emulates nothing again.


if not ONE_JOB:

    rule events:
        input:
            frames="results/{scenario}/{id}/frames.h5",
            trajectory="results/{scenario}/{id}/trajectory.h5",
        output:
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
            code=code("events"),
        shell:
            "traj2events events {input.frames} --output {output.events} --seed {params.seed} --settings {params.settings:q} "
            "--threads {threads} 2> {log}"


rule export_events:
    input:
        unpack(export_inputs),
    output:
        "results/{scenario}/{id}/events.{suffix}",
    log:
        "results/logs/{scenario}/{id}/export_events_{suffix}.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/export_events_{suffix}.tsv"
    wildcard_constraints:
        suffix="|".join(EXPORT_FLAG),
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=resources_of("events", "mem_mb"),
    params:
        flag=lambda wildcards: EXPORT_FLAG[wildcards.suffix],
        options=export_options,
        code=code("export"),
    shell:
        "traj2events export events {input.events} --{params.flag} {output} {params.options} 2> {log}"

# Stage 7: event emulation per trajectory, from the rendered linear radiance (the HDR
# path), with the event-frame mosaic and the exports the config asks for.


rule events:
    input:
        frames="results/{scenario}/{id}/frames.h5",
        trajectory="results/{scenario}/{id}/trajectory.h5",
    output:
        events="results/{scenario}/{id}/events.h5",
        mosaic=report(
            "results/{scenario}/{id}/events.png",
            caption="../report/events.rst",
            category="Events",
            subcategory="{scenario}",
        ),
        **export_outputs("results/{scenario}/{id}"),
    params:
        options=event_options,
        seed=event_seed,
        exports=export_flags,
        code=source_hash("emulator", "figures", "video"),
    log:
        "results/logs/{scenario}/{id}/events.log",
    conda:
        ENV
    shell:
        "traj2events events {input.frames} --output {output.events} --seed {params.seed} {params.options} "
        "--frames-png {output.mosaic} --title '{wildcards.scenario} {wildcards.id}' "
        "--trajectory {input.trajectory} {params.exports} 2> {log}"

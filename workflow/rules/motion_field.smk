# Stage 6: ground-truth motion field per trajectory: over the analytic sphere, and of the
# rendered terrain from its depth.


rule motion_field:
    input:
        trajectory="results/{scenario}/{id}/trajectory.h5",
        frames="results/{scenario}/{id}/frames.h5",
    output:
        field="results/{scenario}/{id}/motion_field.h5",
        flo=directory("results/{scenario}/{id}/flow"),
    log:
        "results/logs/{scenario}/{id}/motion_field.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/motion_field.tsv"
    conda:
        ENV
    resources:
        mem_mb=resources_of("motion_field", "mem_mb"),
        runtime=resources_of("motion_field", "runtime"),
    params:
        settings=settings("motion_field"),
        code=code("motion_field"),
    shell:
        "traj2events motion-field {input.trajectory} --frames {input.frames} --settings {params.settings:q} "
        "--output {output.field} --flo-dir {output.flo} 2> {log}"

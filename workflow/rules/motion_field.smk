# Stage 6: ground-truth motion field per trajectory: over the analytic sphere, and of the
# rendered terrain from its depth.


rule motion_field:
    input:
        trajectory="results/{scenario}/{id}/trajectory.h5",
        frames="results/{scenario}/{id}/frames.h5",
    output:
        field="results/{scenario}/{id}/motion_field.h5",
        flo=directory("results/{scenario}/{id}/flow"),
        figure=report(
            "results/{scenario}/{id}/motion_field.png",
            caption="../report/motion_field.rst",
            category="Motion field",
            subcategory="{scenario}",
        ),
    params:
        width=config["camera"]["width"],
        height=config["camera"]["height"],
        fov_deg=config["camera"]["fov_deg"],
        radius=config["motion_field"]["moon_radius_m"],
        every=config["motion_field"]["every_n_frames"],
        code=source_hash("camera", "motion_field", "figures", "dynamics", "video"),
    log:
        "results/logs/{scenario}/{id}/motion_field.log",
    conda:
        ENV
    shell:
        "traj2events motion-field {input.trajectory} --frames {input.frames} --width {params.width} --height {params.height} "
        "--fov-deg {params.fov_deg} --moon-radius-m {params.radius} --every {params.every} "
        "--output {output.field} --flo-dir {output.flo} --figure {output.figure} 2> {log}"

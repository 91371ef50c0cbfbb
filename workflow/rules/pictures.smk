# Pictures: the frame, motion-field and event-frame mosaics at the paper's five times, and
# the dataset figure. Their own rules, so a picture setting or a figure's style reruns
# pictures only.


rule frames_picture:
    input:
        trajectory="results/{scenario}/{id}/trajectory.h5",
        video="results/{scenario}/{id}/video.mkv",
    output:
        report(
            "results/{scenario}/{id}/frames.png",
            caption="../report/frames.rst",
            category="Frames",
            subcategory="{scenario}",
        ),
    log:
        "results/logs/{scenario}/{id}/frames_picture.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/frames_picture.tsv"
    conda:
        ENV
    params:
        code=code("pictures"),
    shell:
        "traj2events picture frames {input.trajectory} --video {input.video} --output {output} 2> {log}"


rule motion_field_picture:
    input:
        trajectory="results/{scenario}/{id}/trajectory.h5",
        video="results/{scenario}/{id}/video.mkv",
    output:
        report(
            "results/{scenario}/{id}/motion_field.png",
            caption="../report/motion_field.rst",
            category="Motion field",
            subcategory="{scenario}",
        ),
    log:
        "results/logs/{scenario}/{id}/motion_field_picture.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/motion_field_picture.tsv"
    conda:
        ENV
    params:
        settings=settings("camera"),
        code=code("pictures"),
    shell:
        "traj2events picture motion-field {input.trajectory} --settings {params.settings:q} --video {input.video} "
        "--output {output} 2> {log}"


rule events_picture:
    input:
        events="results/{scenario}/{id}/events.h5",
        trajectory="results/{scenario}/{id}/trajectory.h5",
    output:
        report(
            "results/{scenario}/{id}/events.png",
            caption="../report/events.rst",
            category="Events",
            subcategory="{scenario}",
        ),
    log:
        "results/logs/{scenario}/{id}/events_picture.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/events_picture.tsv"
    conda:
        ENV
    params:
        settings=settings("events_picture"),
        code=code("pictures"),
    shell:
        "traj2events picture events {input.events} --trajectory {input.trajectory} "
        "--settings {params.settings:q} --output {output} 2> {log}"


rule dataset_picture:
    input:
        expand("results/{scenario}/solutions.h5", scenario=SOLVED),
    output:
        report(
            "results/figures/trajectories.png",
            caption="../report/trajectories.rst",
            category="Trajectories",
        ),
    log:
        "results/logs/dataset_picture.log",
    benchmark:
        "results/benchmarks/dataset_picture.tsv"
    conda:
        ENV
    params:
        code=code("pictures"),
    shell:
        "traj2events picture dataset {input} --output {output} 2> {log}"


rule dataset_overview:
    input:
        indexes=expand("results/{scenario}/index.csv", scenario=SCENARIOS),
        summary="results/summary.csv",
        # The score tables `traj2events score` wrote (the page shows them): a new one reruns it.
        scores=lambda wildcards: sorted(str(p) for p in Path("results/scores").glob("*.csv")),
    output:
        report(
            "results/overview.html",
            caption="../report/overview.rst",
            category="Dataset",
        ),
    log:
        "results/logs/dataset_overview.log",
    benchmark:
        "results/benchmarks/dataset_overview.tsv"
    conda:
        ENV
    params:
        code=code("overview"),
        config=lambda wildcards: json.dumps(config, sort_keys=True),
    shell:
        "traj2events overview {input.indexes} --summary {input.summary} --config {params.config:q} "
        "--output {output} 2> {log}"

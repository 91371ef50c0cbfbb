# Stages 1-3: base solve per scenario, continuation sampling (failed samples are drawn
# again, so a scenario's trajectory ids come from the config and the DAG is static), and
# camera poses at the frame rate per trajectory; the per-scenario index and the dataset
# summary.


rule base_solution:
    output:
        "results/{scenario}/base.h5",
    log:
        "results/logs/{scenario}/base_solution.log",
    benchmark:
        "results/benchmarks/{scenario}/base_solution.tsv"
    conda:
        ENV
    params:
        settings=settings("solve"),
        code=code("base_solution"),
    shell:
        "traj2events base --settings {params.settings:q} --record-failure --output {output} 2> {log}"


rule sample_trajectories:
    input:
        base="results/{scenario}/base.h5",
    output:
        solutions="results/{scenario}/solutions.h5",
        table="results/{scenario}/samples.csv",
    log:
        "results/logs/{scenario}/sample_trajectories.log",
    benchmark:
        "results/benchmarks/{scenario}/sample_trajectories.tsv"
    conda:
        ENV
    threads: workflow.cores
    resources:
        mem_mb=resources_of("sample_trajectories", "mem_mb"),
        runtime=resources_of("sample_trajectories", "runtime"),
    params:
        settings=settings("solve"),
        code=code("sample_trajectories"),
    shell:
        "traj2events sample --settings {params.settings:q} --base {input.base} "
        "--output {output.solutions} --table {output.table} --jobs {threads} 2> {log}"


rule camera_poses:
    input:
        "results/{scenario}/solutions.h5",
    output:
        "results/{scenario}/{id}/trajectory.h5",
    log:
        "results/logs/{scenario}/{id}/camera_poses.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/camera_poses.tsv"
    wildcard_constraints:
        scenario=one_of(SOLVED),
    conda:
        ENV
    params:
        settings=settings("poses"),
        manoeuvre=settings("manoeuvre"),
        code=code("camera_poses"),
    shell:
        "traj2events upsample --solutions {input} --id {wildcards.id} --settings {params.settings:q} "
        "--manoeuvre {params.manoeuvre:q} --output {output} 2> {log}"


rule external_poses:
    input:
        pose_file,
    output:
        "results/{scenario}/{id}/trajectory.h5",
    log:
        "results/logs/{scenario}/{id}/external_poses.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/external_poses.tsv"
    wildcard_constraints:
        scenario=one_of(EXTERNAL),
    conda:
        ENV
    params:
        settings=settings("external_poses"),
        code=code("external_poses"),
    shell:
        "traj2events poses {input} --id {wildcards.id} --settings {params.settings:q} --output {output} 2> {log}"


rule imu:
    input:
        "results/{scenario}/{id}/trajectory.h5",
    output:
        "results/{scenario}/{id}/imu.h5",
    log:
        "results/logs/{scenario}/{id}/imu.log",
    benchmark:
        "results/benchmarks/{scenario}/{id}/imu.tsv"
    conda:
        ENV
    params:
        settings=settings("imu"),
        seed=trajectory_seed,
        code=code("imu"),
    shell:
        "traj2events imu {input} --settings {params.settings:q} --seed {params.seed} --output {output} 2> {log}"


rule dataset_index:
    input:
        trajectories=scenario_outputs,
        samples=sample_table,
    output:
        "results/{scenario}/index.csv",
    log:
        "results/logs/{scenario}/dataset_index.log",
    benchmark:
        "results/benchmarks/{scenario}/dataset_index.tsv"
    conda:
        ENV
    params:
        samples=lambda wildcards, input: f"--samples {input.samples}" if input.samples else "",
        settings=settings("index"),
        code=code("index"),
    shell:
        "traj2events index {input.trajectories} {params.samples} --settings {params.settings:q} --output {output} 2> {log}"


rule trajectory_summary:
    input:
        solutions=expand("results/{scenario}/solutions.h5", scenario=SOLVED),
        tables=expand("results/{scenario}/samples.csv", scenario=SOLVED),
    output:
        # In the report through the overview, which shows it in place (a CSV entry would only download).
        "results/summary.csv",
    log:
        "results/logs/trajectory_summary.log",
    benchmark:
        "results/benchmarks/trajectory_summary.tsv"
    conda:
        ENV
    params:
        code=code("summary"),
    shell:
        "traj2events summary --solutions {input.solutions} --tables {input.tables} --output {output} 2> {log}"

# traj2events: synthetic event-camera datasets from mass-optimal lunar landings.
#
#   snakemake --cores 2                              # the default dataset (+ config/config.yaml)
#   snakemake --cores 2 --configfile config/paper.yaml
#
# Config files are overlays on the package's defaults (src/traj2events/defaults.yaml).
# Stages: base solve per scenario -> continuation sampling -> camera poses -> rendering
# (frames, videos) -> motion-field ground truth (sphere and rendered terrain) -> events
# (and their exports); pictures of each; the index and summary.
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/trajectories.smk"
include: "workflow/rules/render.smk"
include: "workflow/rules/motion_field.smk"
include: "workflow/rules/events.smk"
include: "workflow/rules/pictures.smk"


rule all:
    default_target: True
    input:
        all_outputs,

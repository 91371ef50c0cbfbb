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

from traj2events.config import ConfigError, load_yaml

# Snakemake's own reader answers a file that is not UTF-8 YAML with a traceback; ours names
# the file and the fault. (Files given by --configfile Snakemake reads before this line.)
try:
    load_yaml("config/config.yaml", missing_ok=True)
except ConfigError as error:
    raise WorkflowError(f"invalid configuration: {error}")


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

# Circular-actuator characterisation workflow.
# `snakemake --cores 2` turns every dataset of config.yaml into angles, hysteresis curves, a
# model-versus-data comparison and results/report.pdf.  All logic lives in the `pipeline` package;
# the rules under rules/ only name files and call `python -m pipeline ...`.

from snakemake.utils import min_version

min_version("8.0")


configfile: "config.yaml"


include: "rules/common.smk"
include: "rules/cluster.smk"
include: "rules/acquire.smk"
include: "rules/measure.smk"
include: "rules/aggregate.smk"
include: "rules/model.smk"
include: "rules/compare.smk"
include: "rules/bench.smk"
include: "rules/force.smk"
include: "rules/video.smk"
include: "rules/report.smk"


rule all:
    default_target: True
    input:
        report=f"{RESULTS}/report.pdf",


onsuccess:
    import sys

    from pipeline.photoset_measure import remove_stale_report, run_summaries

    for line in run_summaries(
        {name: f"{RESULTS}/datasets/{name}/angles.csv" for name in DATASETS},
        {name: log_file(f"measure/{name}") for name in DATASETS},
    ):
        print(line, file=sys.stderr)
    remove_stale_report(Path(f"{RESULTS}/report.pdf"))


onerror:
    import sys

    from pipeline.photoset_measure import set_aside_stale_report

    stale = set_aside_stale_report(
        Path(f"{RESULTS}/report.pdf"),
        [Path(f"{RESULTS}/datasets/{name}/angles.csv") for name in DATASETS],
    )
    if stale is not None:
        print(
            f"The run stopped before it made the report again: the earlier run's, which does not "
            f"show what changed since, is now {stale}. Run again (once what is said above, if "
            "anything, is fixed).",
            file=sys.stderr,
        )

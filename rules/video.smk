# Video datasets (pipeline.video): synthetic videos are rendered, rig videos recorded, and every
# video dataset gets its continuous aggregation (loops, settling curves, step responses) for its
# report page.  A folder dataset is a video dataset when its manifest lists videos.
from pipeline.video.workflow import is_video_dataset, names_pattern, profile_options

VIDEO_DATASETS = [name for name, ds in DATASETS.items() if is_video_dataset(ds)]
VIDEO_CONTINUOUS = [f"{RESULTS}/continuous/{name}" for name in VIDEO_DATASETS]


ruleorder: synth_video > synth_photoset
ruleorder: acquire_rig_video > acquire_rig


rule synth_video:
    output:
        directory(f"{RESULTS}/photosets/{{video_dataset}}"),
    wildcard_constraints:
        video_dataset=names_pattern([n for n in VIDEO_DATASETS if DATASETS[n]["source"] == "synthetic_video"]),
    params:
        ds=lambda wc: DATASETS[wc.video_dataset],
        profile=lambda wc: profile_options(DATASETS[wc.video_dataset]),
        overrides=lambda wc: scene_overrides(DATASETS[wc.video_dataset]),
    log:
        f"{LOGS}/synth_video/{{video_dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/synth_video/{{video_dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=60,
    shell:
        "python -m pipeline synth-video {output} --material {params.ds[material]} {params.profile}"
        " --codec {params.ds[codec]} --scene {params.ds[scene]} --seed {params.ds[seed]} {params.overrides} > {log} 2>&1"


rule acquire_rig_video:
    output:
        touch(f"{RESULTS}/acquired/{{video_dataset}}.done"),
    wildcard_constraints:
        video_dataset=names_pattern([n for n in VIDEO_DATASETS if DATASETS[n]["source"] == "rig"]),
    params:
        ds=lambda wc: DATASETS[wc.video_dataset],
        profile=lambda wc: profile_options(DATASETS[wc.video_dataset]),
        camera=lambda wc: DATASETS[wc.video_dataset]["camera"],
    log:
        f"{LOGS}/acquire/{{video_dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/acquire/{{video_dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=240,
    shell:
        "python -m pipeline acquire --record video --port {params.ds[port]} --camera {params.camera:q}"
        " --material {params.ds[material]} --actuator {params.ds[actuator]} --trials {params.ds[trials]}"
        " {params.profile} --l0-mm {params.ds[l0_mm]} --out {params.ds[path]} > {log} 2>&1"


rule continuous:
    input:
        angles=f"{RESULTS}/datasets/{{dataset}}/angles.csv",
        overlays=f"{RESULTS}/datasets/{{dataset}}/overlays",
    output:
        directory(f"{RESULTS}/continuous/{{dataset}}"),
    params:
        bin=lambda wc: f"--bin-kpa {config['aggregate']['bin_kpa']}" if config["aggregate"]["bin_kpa"] else "",
        flagged="--include-flagged" if config["aggregate"]["include_flagged"] else "",
    log:
        f"{LOGS}/continuous/{{dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/continuous/{{dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=10,
    shell:
        "python -m pipeline continuous {input.angles} --out-dir {output} --overlays {input.overlays}"
        " {params.bin} {params.flagged} > {log} 2>&1"

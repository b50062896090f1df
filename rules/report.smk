# The PDF report a lab hands to its advisor.


rule report:
    input:
        angles=per_dataset("{results}/datasets/{dataset}/angles.csv"),
        hysteresis=per_dataset("{results}/datasets/{dataset}/hysteresis.csv"),
        rms=f"{RESULTS}/rms.csv",
        config=f"{RESULTS}/config.resolved.yaml",
        curves=expand(f"{RESULTS}/model/{{material}}.csv", material=MATERIALS),
        bench=f"{RESULTS}/bench/default" if config["bench"]["in_report"] else [],
        force=FORCE_OUTPUTS,
        video=VIDEO_CONTINUOUS,
    output:
        f"{RESULTS}/report.pdf",
    params:
        photosets=[photoset_dir(n) for n in DATASETS],
        overlays=per_dataset("{results}/datasets/{dataset}/overlays"),
        names=list(DATASETS),
        bench=lambda wc, input: f"--bench-dir {input.bench}" if input.bench else "",
        force=f"--force-dir {RESULTS}/force" if FORCE_OUTPUTS else "",
        video=lambda wc, input: f"--video-dirs {' '.join(input.video)}" if input.video else "",
        title=config["report"]["title"],
    log:
        f"{LOGS}/report.log",
    benchmark:
        f"{BENCHMARKS}/report.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=2000,
        runtime=10,
    shell:
        "python -m pipeline report --datasets {params.names} --angles {input.angles}"
        " --hysteresis {input.hysteresis} --rms {input.rms} --model-curves {input.curves}"
        " --photosets {params.photosets} --overlays {params.overlays} {params.bench} {params.force} {params.video}"
        " --config {input.config} --title {params.title:q} --out {output} > {log} 2>&1"


rule resolved_config:
    output:
        f"{RESULTS}/config.resolved.yaml",
    params:
        config=config,
    log:
        f"{LOGS}/resolved_config.log",
    benchmark:
        f"{BENCHMARKS}/resolved_config.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=200,
        runtime=1,
    run:
        from pipeline.config import write_resolved_config

        write_resolved_config(params.config, output[0])

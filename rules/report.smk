# The PDF report a lab hands to its advisor.


rule report:
    input:
        angles=per_dataset("{results}/datasets/{dataset}/angles.csv"),
        hysteresis=per_dataset("{results}/datasets/{dataset}/hysteresis.csv"),
        rms=f"{RESULTS}/rms.csv",
        config=f"{RESULTS}/config.resolved.yaml",
        curves=expand(f"{RESULTS}/model/{{material}}.csv", material=MATERIALS)
        + OWN_MODEL_CURVES
        + [f"{RESULTS}/compare_curves.csv"],
        materials=MATERIALS_FILES,
        bench=f"{RESULTS}/bench/default" if config["bench"]["in_report"] else [],
        force=FORCE_OUTPUTS,
        video=VIDEO_CONTINUOUS,
    output:
        f"{RESULTS}/report.pdf",
    params:
        photosets=[photoset_dir(n) for n in DATASETS],
        overlays=per_dataset("{results}/datasets/{dataset}/overlays"),
        names=list(DATASETS),
        bench=lambda wc, input: ["--bench-dir", input.bench] if input.bench else [],
        force=["--force-dir", f"{RESULTS}/force"] if FORCE_OUTPUTS else [],
        video=lambda wc, input: ["--video-dirs", *input.video] if input.video else [],
        materials=lambda wc, input: ["--materials-files", *input.materials] if input.materials else [],
        title=config["report"]["title"],
    log:
        log_file("report"),
    benchmark:
        benchmark_file("report")
    threads: 1
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline report --datasets {params.names:q} --angles {input.angles:q}"
            " --hysteresis {input.hysteresis:q} --rms {input.rms:q} --model-curves {input.curves:q}"
            " --photosets {params.photosets:q} --overlays {params.overlays:q}"
            " {params.bench:q} {params.force:q} {params.video:q} {params.materials:q} --config {input.config:q} --title {params.title:q}"
            " --out {output:q}"
        )


rule resolved_config:
    output:
        f"{RESULTS}/config.resolved.yaml",
    params:
        config=config,
    log:
        log_file("resolved_config"),
    benchmark:
        benchmark_file("resolved_config")
    threads: 1
    resources:
        **SMALL_JOB,
    conda:
        CONDA_ENV
    run:
        from pipeline.config import write_resolved_config

        write_resolved_config(params.config, output[0])

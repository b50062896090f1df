# Acquisition: synthetic photo sets are rendered here; rig datasets are acquired into their own
# folder (outside results/, never an output Snakemake could delete) and marked done by a flag.


rule synth_photoset:
    output:
        directory(f"{RESULTS}/photosets/{{dataset}}"),
    params:
        ds=lambda wc: DATASETS[wc.dataset],
        overrides=lambda wc: scene_overrides(DATASETS[wc.dataset]),
    log:
        log_file("synth/{dataset}"),
    benchmark:
        benchmark_file("synth/{dataset}")
    threads: 2
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline synth {output:q} --material {params.ds[material]:q}"
            " --actuators {params.ds[actuators]:q} --trials {params.ds[trials]:q}"
            " --seed {params.ds[seed]:q} --scene {params.ds[scene]:q}"
            " --step-kpa {params.ds[step_kpa]:q} --max-kpa {params.ds[max_kpa]:q}"
            " {params.overrides:q} --jobs {threads}"
        )


rule acquire_rig:
    output:
        touch(f"{RESULTS}/acquired/{{dataset}}.done"),
    params:
        ds=lambda wc: DATASETS[wc.dataset],
    log:
        log_file("acquire/{dataset}"),
    benchmark:
        benchmark_file("acquire/{dataset}")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=240,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline acquire --port {params.ds[port]:q} --camera {params.ds[camera]:q}"
            " --material {params.ds[material]:q} --actuator {params.ds[actuator]:q}"
            " --trials {params.ds[trials]:q} --step-kpa {params.ds[step_kpa]:q}"
            " --max-kpa {params.ds[max_kpa]:q} --settle-s {params.ds[settle_s]:q}"
            " --l0-mm {params.ds[l0_mm]:q} --out {params.ds[path]:q}"
        )

# Acquisition: synthetic photo sets are rendered here; rig datasets are acquired into their own
# folder (outside results/, never an output Snakemake could delete) and marked done by a flag.


rule synth_photoset:
    output:
        directory(f"{RESULTS}/photosets/{{dataset}}"),
    params:
        ds=lambda wc: DATASETS[wc.dataset],
        overrides=lambda wc: scene_overrides(DATASETS[wc.dataset]),
    log:
        f"{LOGS}/synth/{{dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/synth/{{dataset}}.tsv"
    threads: 2
    conda:
        CONDA_ENV
    resources:
        mem_mb=2000,
        runtime=30,
    shell:
        "python -m pipeline synth {output} --material {params.ds[material]}"
        " --actuators {params.ds[actuators]} --trials {params.ds[trials]} --seed {params.ds[seed]}"
        " --scene {params.ds[scene]} --step-kpa {params.ds[step_kpa]} --max-kpa {params.ds[max_kpa]}"
        " {params.overrides} --jobs {threads} > {log} 2>&1"


rule acquire_rig:
    output:
        touch(f"{RESULTS}/acquired/{{dataset}}.done"),
    params:
        ds=lambda wc: DATASETS[wc.dataset],
        camera=lambda wc: DATASETS[wc.dataset]["camera"],
    log:
        f"{LOGS}/acquire/{{dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/acquire/{{dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=240,
    shell:
        "python -m pipeline acquire --port {params.ds[port]} --camera {params.camera:q}"
        " --material {params.ds[material]} --actuator {params.ds[actuator]}"
        " --trials {params.ds[trials]} --step-kpa {params.ds[step_kpa]} --max-kpa {params.ds[max_kpa]}"
        " --settle-s {params.ds[settle_s]} --l0-mm {params.ds[l0_mm]} --out {params.ds[path]} > {log} 2>&1"

# Blocked force and eccentricity (paper Figs. 7A/7B) and grasp logs (Fig. 8B). Without force
# datasets and without a grasp log nothing here runs and the report has no force pages.


rule force_synth_photoset:
    output:
        directory(f"{RESULTS}/force_photosets/{{force_dataset}}"),
    params:
        ds=lambda wc: FORCE_DATASETS[wc.force_dataset],
    log:
        f"{LOGS}/force_synth/{{force_dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/force_synth/{{force_dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=20,
    shell:
        "python -m pipeline force synth {output} --material {params.ds[material]}"
        " --actuators {params.ds[actuators]} --trials {params.ds[trials]} --seed {params.ds[seed]}"
        " --scene {params.ds[scene]} --step-kpa {params.ds[step_kpa]} > {log} 2>&1"


rule force_measure:
    input:
        force_photoset_input,
    output:
        f"{RESULTS}/force/datasets/{{force_dataset}}/eccentricity.csv",
    params:
        folder=lambda wc: force_photoset_dir(wc.force_dataset),
    log:
        f"{LOGS}/force_measure/{{force_dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/force_measure/{{force_dataset}}.tsv"
    threads: 2
    conda:
        CONDA_ENV
    resources:
        mem_mb=2000,
        runtime=20,
    shell:
        "python -m pipeline force measure {params.folder} --out {output} --jobs {threads} > {log} 2>&1"


rule force_aggregate:
    input:
        expand(f"{RESULTS}/force/datasets/{{name}}/eccentricity.csv", name=list(FORCE_DATASETS)),
    output:
        force=f"{RESULTS}/force/force_summary.csv",
        eccentricity=f"{RESULTS}/force/eccentricity_summary.csv",
    log:
        f"{LOGS}/force_aggregate.log",
    benchmark:
        f"{BENCHMARKS}/force_aggregate.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=10,
    shell:
        "python -m pipeline force aggregate {input} --out {output.force}"
        " --eccentricity-out {output.eccentricity} > {log} 2>&1"


rule force_grasp:
    input:
        config["force"]["grasp_log"] or [],
    output:
        f"{RESULTS}/force/grasp_summary.csv",
    log:
        f"{LOGS}/force_grasp.log",
    benchmark:
        f"{BENCHMARKS}/force_grasp.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=500,
        runtime=5,
    shell:
        "python -m pipeline force grasp {input} --out {output} > {log} 2>&1"

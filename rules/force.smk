# Blocked force and eccentricity (paper Figs. 7A/7B) and grasp logs (Fig. 8B). Without force
# datasets and without a grasp log nothing here runs and the report has no force pages.


rule force_synth_photoset:
    output:
        directory(f"{RESULTS}/force_photosets/{{force_dataset}}"),
    params:
        ds=lambda wc: FORCE_DATASETS[wc.force_dataset],
    log:
        log_file("force_synth/{force_dataset}"),
    benchmark:
        benchmark_file("force_synth/{force_dataset}")
    threads: 1
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline force synth {output:q} --material {params.ds[material]:q}"
            " --actuators {params.ds[actuators]:q} --trials {params.ds[trials]:q}"
            " --seed {params.ds[seed]:q} --scene {params.ds[scene]:q}"
            " --step-kpa {params.ds[step_kpa]:q}"
        )


rule force_measure:
    input:
        force_photoset_input,
    output:
        f"{RESULTS}/force/datasets/{{force_dataset}}/eccentricity.csv",
    params:
        folder=lambda wc: force_photoset_dir(wc.force_dataset),
    log:
        log_file("force_measure/{force_dataset}"),
    benchmark:
        benchmark_file("force_measure/{force_dataset}")
    threads: 2
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline force measure {params.folder:q} --out {output:q} --jobs {threads}"
        )


rule force_aggregate:
    input:
        expand(f"{RESULTS}/force/datasets/{{name}}/eccentricity.csv", name=list(FORCE_DATASETS)),
    output:
        force=f"{RESULTS}/force/force_summary.csv",
        eccentricity=f"{RESULTS}/force/eccentricity_summary.csv",
    log:
        log_file("force_aggregate"),
    benchmark:
        benchmark_file("force_aggregate")
    threads: 1
    resources:
        **TABLE_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline force aggregate {input:q} --out {output.force:q}"
            " --eccentricity-out {output.eccentricity:q}"
        )


rule force_grasp:
    input:
        config["force"]["grasp_log"] or [],
    output:
        f"{RESULTS}/force/grasp_summary.csv",
    log:
        log_file("force_grasp"),
    benchmark:
        benchmark_file("force_grasp")
    threads: 1
    resources:
        **SMALL_JOB,
    conda:
        CONDA_ENV
    shell:
        logged("python -m pipeline force grasp {input:q} --out {output:q}")

# Analytical model: the psi <-> P curve of every material the datasets hold, from the run's
# materials file (results/model/) or from a dataset's own (under that dataset's results).


rule model_curve:
    input:
        config["model"]["materials_file"] or [],
    output:
        f"{RESULTS}/model/{{material}}.csv",
    params:
        materials=materials_option(),
        readings=model_readings_option(),
    log:
        log_file("model/{material}"),
    benchmark:
        benchmark_file("model/{material}")
    threads: 1
    resources:
        **SMALL_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline model curve --material {wildcards.material:q} {params.materials:q}"
            " {params.readings:q} --out {output:q}"
        )


rule model_curve_dataset:
    input:
        lambda wc: materials_file(DATASETS[wc.dataset]) or [],
    output:
        f"{RESULTS}/datasets/{{dataset}}/model/{{material}}.csv",
    params:
        materials=lambda wc: ["--materials", materials_file(DATASETS[wc.dataset])],
        readings=model_readings_option(),
    log:
        log_file("datasets/{dataset}/model/{material}"),
    benchmark:
        benchmark_file("datasets/{dataset}/model/{material}")
    threads: 1
    resources:
        **SMALL_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline model curve --material {wildcards.material:q} {params.materials:q}"
            " {params.readings:q} --out {output:q}"
        )

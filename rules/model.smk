# Analytical model: the psi <-> P curve of every material the datasets hold.


rule model_curve:
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

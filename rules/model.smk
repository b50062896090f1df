# Analytical model: the psi <-> P curve of every material the datasets hold.


rule model_curve:
    output:
        f"{RESULTS}/model/{{material}}.csv",
    params:
        materials=materials_option(),
        readings=model_readings_option(),
    log:
        f"{LOGS}/model/{{material}}.log",
    benchmark:
        f"{BENCHMARKS}/model/{{material}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=500,
        runtime=5,
    shell:
        "python -m pipeline model curve --material {wildcards.material} {params.materials}"
        " {params.readings}"
        " --out {output} > {log} 2>&1"

# Model versus data: RMS, crossings, range of motion, fitted k_P, for every dataset and material.


rule compare:
    input:
        hysteresis=per_dataset("{results}/datasets/{dataset}/hysteresis.csv"),
        angles=per_dataset("{results}/datasets/{dataset}/angles.csv"),
    output:
        f"{RESULTS}/rms.csv",
    params:
        names=list(DATASETS),
        materials=materials_option(),
        readings=model_readings_option(),
        bootstrap=config["compare"]["bootstrap"],
        seed=config["compare"]["seed"],
    log:
        f"{LOGS}/compare.log",
    benchmark:
        f"{BENCHMARKS}/compare.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=10,
    shell:
        "python -m pipeline compare {input.hysteresis} --angles {input.angles} --datasets {params.names}"
        " --bootstrap {params.bootstrap} --seed {params.seed} {params.materials} {params.readings} --out {output} > {log} 2>&1"

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
        log_file("compare"),
    benchmark:
        benchmark_file("compare")
    threads: 1
    resources:
        **TABLE_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline compare {input.hysteresis:q} --angles {input.angles:q}"
            " --datasets {params.names:q} --bootstrap {params.bootstrap:q} --seed {params.seed:q}"
            " {params.materials:q} {params.readings:q} --out {output:q}"
        )

# Model versus data: RMS, crossings, range of motion, fitted k_P, per material, l0 and materials
# file (each dataset's own actuator), with the model curve every RMS was computed against.


rule compare:
    input:
        hysteresis=per_dataset("{results}/datasets/{dataset}/hysteresis.csv"),
        angles=per_dataset("{results}/datasets/{dataset}/angles.csv"),
        materials=MATERIALS_FILES,
    output:
        rms=f"{RESULTS}/rms.csv",
        curves=f"{RESULTS}/compare_curves.csv",
    params:
        names=list(DATASETS),
        photosets=[photoset_dir(n) for n in DATASETS],
        materials=materials_option(),
        dataset_materials=dataset_materials_option(),
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
            " --datasets {params.names:q} --photosets {params.photosets:q} --bootstrap {params.bootstrap:q}"
            " --seed {params.seed:q} {params.materials:q} {params.dataset_materials:q} {params.readings:q} --out {output.rms:q} --curves {output.curves:q}"
        )

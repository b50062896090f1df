# Model versus data: RMS, crossings, range of motion, fitted k_P, per material and l0 (each
# dataset's own actuator), with the model curve every RMS was computed against.


rule compare:
    input:
        hysteresis=per_dataset("{results}/datasets/{dataset}/hysteresis.csv"),
        angles=per_dataset("{results}/datasets/{dataset}/angles.csv"),
    output:
        rms=f"{RESULTS}/rms.csv",
        curves=f"{RESULTS}/compare_curves.csv",
    params:
        names=list(DATASETS),
        photosets=[photoset_dir(n) for n in DATASETS],
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
        " --photosets {params.photosets:q} --bootstrap {params.bootstrap} --seed {params.seed} {params.materials}"
        " {params.readings} --out {output.rms} --curves {output.curves} > {log} 2>&1"

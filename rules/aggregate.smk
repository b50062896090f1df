# Aggregation: mean +- sd of psi per material x direction x pressure level, per dataset.


rule aggregate:
    input:
        angles=f"{RESULTS}/datasets/{{dataset}}/angles.csv",
    output:
        hysteresis=f"{RESULTS}/datasets/{{dataset}}/hysteresis.csv",
        per_actuator=f"{RESULTS}/datasets/{{dataset}}/hysteresis_per_actuator.csv",
    params:
        bin=["--bin-kpa", config["aggregate"]["bin_kpa"]] if config["aggregate"]["bin_kpa"] else [],
        flagged=["--include-flagged"] if config["aggregate"]["include_flagged"] else [],
    log:
        log_file("aggregate/{dataset}"),
    benchmark:
        benchmark_file("aggregate/{dataset}")
    threads: 1
    resources:
        **TABLE_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "python -m pipeline aggregate {input.angles:q} --out {output.hysteresis:q}"
            " --per-actuator-out {output.per_actuator:q} {params.bin:q} {params.flagged:q}"
        )

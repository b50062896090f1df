# Aggregation: mean +- sd of psi per material x direction x pressure level, per dataset.


rule aggregate:
    input:
        angles=f"{RESULTS}/datasets/{{dataset}}/angles.csv",
    output:
        hysteresis=f"{RESULTS}/datasets/{{dataset}}/hysteresis.csv",
        per_actuator=f"{RESULTS}/datasets/{{dataset}}/hysteresis_per_actuator.csv",
    params:
        bin=lambda wc: f"--bin-kpa {config['aggregate']['bin_kpa']}" if config["aggregate"]["bin_kpa"] else "",
        flagged="--include-flagged" if config["aggregate"]["include_flagged"] else "",
    log:
        f"{LOGS}/aggregate/{{dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/aggregate/{{dataset}}.tsv"
    threads: 1
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
        runtime=10,
    shell:
        "python -m pipeline aggregate {input.angles} --out {output.hysteresis}"
        " --per-actuator-out {output.per_actuator} {params.bin} {params.flagged} > {log} 2>&1"

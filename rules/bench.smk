# Speed/accuracy and stability study. A small grid feeds the default report; `snakemake bench`
# runs the full grid.


rule bench_default:
    output:
        directory(f"{RESULTS}/bench/default"),
    log:
        f"{LOGS}/bench/default.log",
    benchmark:
        f"{BENCHMARKS}/bench/default.tsv"
    threads: 2
    conda:
        CONDA_ENV
    resources:
        mem_mb=2000,
        runtime=30,
    shell:
        "python -m pipeline bench --grid default --jobs {threads} --out {output} > {log} 2>&1"


rule bench_full:
    output:
        directory(f"{RESULTS}/bench/full"),
    log:
        f"{LOGS}/bench/full.log",
    benchmark:
        f"{BENCHMARKS}/bench/full.tsv"
    threads: 2
    conda:
        CONDA_ENV
    resources:
        mem_mb=4000,
        runtime=120,
    shell:
        "python -m pipeline bench --grid full --jobs {threads} --out {output} > {log} 2>&1"


rule bench:
    input:
        rules.bench_full.output,

# Speed/accuracy and stability study. A small grid feeds the default report; `snakemake bench`
# runs the full grid.


rule bench_default:
    output:
        directory(f"{RESULTS}/bench/default"),
    log:
        log_file("bench/default"),
    benchmark:
        benchmark_file("bench/default")
    threads: 2
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged("python -m pipeline bench study --grid default --jobs {threads} --out {output:q}")


rule bench_full:
    output:
        directory(f"{RESULTS}/bench/full"),
    log:
        log_file("bench/full"),
    benchmark:
        benchmark_file("bench/full")
    threads: 2
    resources:
        mem_mb=4000,
        runtime=120,
    conda:
        CONDA_ENV
    shell:
        logged("python -m pipeline bench study --grid full --jobs {threads} --out {output:q}")


rule bench:
    input:
        rules.bench_full.output,

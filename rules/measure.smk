# Measurement: one job per photo set (never per image), parallel inside the job.


rule measure:
    input:
        photoset_input,
    output:
        angles=f"{RESULTS}/datasets/{{dataset}}/angles.csv",
        overlays=directory(f"{RESULTS}/datasets/{{dataset}}/overlays"),
    params:
        folder=lambda wc: photoset_dir(wc.dataset),
        method=measure_method_option(),
        overlays=lambda wc, output: overlays_option(output.overlays),
    log:
        f"{LOGS}/measure/{{dataset}}.log",
    benchmark:
        f"{BENCHMARKS}/measure/{{dataset}}.tsv"
    threads: config["measure"]["jobs"]
    conda:
        CONDA_ENV
    resources:
        mem_mb=2000,
        runtime=30,
    shell:
        "mkdir -p {output.overlays} && python -m pipeline measure {params.folder} --out {output.angles}"
        " {params.method} {params.overlays} --jobs {threads} > {log} 2>&1"

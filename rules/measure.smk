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
        log_file("measure/{dataset}"),
    benchmark:
        benchmark_file("measure/{dataset}")
    threads: config["measure"]["jobs"]
    resources:
        **PHOTO_JOB,
    conda:
        CONDA_ENV
    shell:
        logged(
            "mkdir -p {output.overlays:q} && python -m pipeline measure {params.folder:q}"
            " --out {output.angles:q} {params.method:q} {params.overlays:q} --jobs {threads}"
        )

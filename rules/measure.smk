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
        # each photo's measurement, kept across runs (not an output: an interrupted job keeps it)
        cache=lambda wc: f"{RESULTS}/cache/measure/{wc.dataset}",
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
            " --cache {params.cache:q}"
        )

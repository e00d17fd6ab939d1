"""Input and output, the first and last stages of the pipeline.

Video and camera sources, the pose file (SPEC 9), its CSV, the overlay video, and files
written whole or not at all.

Nothing here knows how a pose is found; the tracker's per-frame answer is `upperpose.result`.
"""

"""Development tooling, not the product.

Synthetic clips with exact truth (`synth`), scoring
(`evaluate`), the thesis' comparison of optimisers (`compare`), dev-set runners (`devset`,
`features_devset`), the confidence tables' re-measurement (`confidence`), the BVH round trip
(`bvh_roundtrip`), refits and benches.
`lab` imports the product; the product never imports `lab`.
"""

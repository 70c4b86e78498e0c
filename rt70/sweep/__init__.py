"""Parameter sweeps over grids of pointings, winds and scene parameters, on Dask."""

"""Star catalogs and what is built from them: Hipparcos, Gaia, the navigation catalog, k-vector, address index, field selection, apparent place."""

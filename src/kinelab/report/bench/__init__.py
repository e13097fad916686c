"""``kinelab bench``: the protocol (:mod:`~kinelab.report.bench.protocol`), kinelab's solvers as adapters
(:mod:`~kinelab.report.bench.adapters`), the peer libraries (:mod:`~kinelab.report.bench.peers`), the
runner (:mod:`~kinelab.report.bench.runner`) and the chain-length scaling
(:mod:`~kinelab.report.bench.scaling`)."""

"""Reports: ``kinelab validate`` (:mod:`~kinelab.report.validate`, rendered by
:mod:`~kinelab.report.render`) and ``kinelab bench`` (:mod:`~kinelab.report.bench`)."""

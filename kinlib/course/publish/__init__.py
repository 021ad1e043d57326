"""What runs on the instructor's machine to publish the course (``kinlib handouts``): problem and solution
pages (:mod:`.handouts`, :mod:`.pages`, :mod:`.analysis`, the reading aids :mod:`.aids`), the executed notebooks (:mod:`.execute`), the PDFs
(:mod:`.printing`) and the in-browser JupyterLite site (:mod:`.lite`, with :mod:`.npm` for its pinned assets).

Importing this package imports nothing (import the modules you need).
"""

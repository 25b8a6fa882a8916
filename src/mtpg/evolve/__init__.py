"""Evolution: initialisation, variation, multi-task selection and the generational loop."""

# Installation and package export are completed by the build/install work; placeholder.

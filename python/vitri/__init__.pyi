from ._vitri import (Cancelled as Cancelled, DegenerateNeighbourhood as DegenerateNeighbourhood,
                     Delaunay as Delaunay, Error as Error, InvalidArgument as InvalidArgument,
                     InvalidPoint as InvalidPoint, LimitError as LimitError, LocalRbf as LocalRbf, Mesh as Mesh,
                     Mesher as Mesher, NumericalError as NumericalError, OrientationError as OrientationError,
                     ParseError as ParseError, Rbf as Rbf, UnknownConstraint as UnknownConstraint, mesh_constraints as mesh_constraints, read as read,
                     reconstruct as reconstruct, write as write)

__version__: str

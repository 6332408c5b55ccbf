"""FE pipeline: spring parameters -> paddle geometry -> CalculiX deck -> ccx run -> results -> tables -> sweep."""

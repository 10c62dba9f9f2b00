/* placeholder */ typedef int iris_placeholder_unit_;

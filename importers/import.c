/* placeholder: implemented by the module's issue work */
typedef int iris_placeholder_unit_;
